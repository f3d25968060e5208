#pragma once
// Image-based lighting for the raster passes: the split-sum approximation of Karis 2013 ("Real Shading
// in Unreal Engine 4", SIGGRAPH course notes, pp. 5-7) for the specular lobe, and irradiance by
// spherical harmonics (Ramamoorthi and Hanrahan 2001, "An Efficient Representation for Irradiance
// Environment Maps") for the diffuse lobe, both for the glTF BRDF of shaders/common/brdf.glsl:
//
//   L_spec(v) ~ Lpre(R, roughness) * [ (1 - m)(f0_ior A + B) + m (baseColor A + B) ]     (Karis eq. 8)
//   A(mu, r) = integral V 4 (n.l)(v.h)/(n.h) (1 - Fc) over GGX-sampled h,  B the same with Fc,
//             Fc = (1 - v.h)^5, V the height-correlated Smith visibility (glTF Appendix B);
//   Lpre(R, r) = sum L(l) (n.l) / sum (n.l) over GGX-sampled l around n = v = R (Karis' N = V = R);
//   L_diff(v) = baseColor (1 - m)(1 - t) (1 - f0_ior)(1 - Dp(mu)) E(n) / pi,
//   Dp(mu) = integral Fc(v.h) cos / pi: the Fresnel weight glTF's fresnel_mix takes from the diffuse
//            base (it depends on mu only, since h = (v + l)/|v + l| does not depend on roughness);
//   E(n) = sum over l <= 2 of A_l L_lm Y_lm(n), A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4.
// Under a uniform environment of radiance 1, A + B + (1 - Dp) ... reproduce the BRDF's directional
// albedo up to the table resolution: the white-furnace test (tests/gl/content) checks it within 2%.
#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/Image.h"
#include "renderer/raytracing/Cancel.h"

namespace radiant::ibl {

constexpr int kDfgSize = 32;         // mu = (i + 0.5) / 32, roughness = j / 31
constexpr int kPrefilterWidth = 64, kPrefilterHeight = 32;
constexpr int kPrefilterLevels = 6;  // roughness k / 5

// RGBA float texels, row j = roughness j / (kDfgSize - 1), column i = mu (i + 0.5) / kDfgSize:
// (A, B, Dp, 0). Computed once (thread-safe).
const std::vector<float>& dfgTable();
// The same quantities at one point, evaluated directly (for tests): {A, B, Dp}.
glm::vec3 dfgAt(float mu, float roughness, int samples = 4096);

// kPrefilterLevels equirect images of kPrefilterWidth x kPrefilterHeight, RGBA, level k for roughness
// k / (kPrefilterLevels - 1), laid out level after level (a 2D array texture).
std::vector<float> prefilterEnvironment(const Image& map, const rt::Cancel& cancel = {});

// The 9 SH coefficients of the irradiance E(n) = sum c_i Y_i(n), already multiplied by A_l
// (evaluate with irradianceFromSh).
std::array<glm::vec3, 9> irradianceSh(const Image& map, const rt::Cancel& cancel = {});
glm::vec3 irradianceFromSh(const std::array<glm::vec3, 9>& sh, const glm::vec3& n);

}  // namespace radiant::ibl

// ---- GL side: the textures and uniforms both raster users (direct: specular; ambient_occlusion:
// diffuse) bind. Declared and uploaded at most once per environment (cache entries keyed by it).
namespace radiant {
class FrameResources;
namespace gl {
class Program;
}
}  // namespace radiant

namespace radiant::ibl {

enum Mode : int { kNone = 0, kUniform = 1, kMap = 2 };
// What lights the frame from afar: the environment map, else a uniform ambient, else nothing.
int modeFor(const FrameResources& res);
// Declares (prepare) the DFG table "ibl_dfg" and, with a map, "ibl_prefiltered" and the SH
// coefficients; uploads what changed. Call from prepare().
void prepare(FrameResources& res);
// Binds the DFG table to `dfgUnit` and the prefiltered map to `prefilteredUnit` (-1 = not needed),
// and sets u_iblMode, u_iblUniform and u_sh[9] on `program`.
void bind(FrameResources& res, const gl::Program& program, int dfgUnit, int prefilteredUnit);

}  // namespace radiant::ibl

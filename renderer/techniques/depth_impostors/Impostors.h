#pragma once
// The GPU side of hierarchical depth impostors (thesis 8.1.1-8.1.2): the view and light impostors
// of every block in two atlases, and the K light slices. Built from a BlockSet for one view axis and
// one light, and cached by the technique under exactly those inputs (the impostors are redrawn only
// when the medium, the parameters, the camera or the light change). Tests drive it directly.
#include <vector>

#include <glm/glm.hpp>

#include "renderer/gl/Gl.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/techniques/depth_impostors/Blocks.h"  // renderer/frame/GpuTypes.h

namespace radiant::gpu {
#include "shaders/depth_impostors/shared.h"  // ImpostorBlock, its bindings and the slice limit

static_assert(sizeof(ImpostorBlock) == 64, "std430 ImpostorBlock must be 64 bytes");
}  // namespace radiant::gpu

namespace radiant::impostors {

// How rays cross the blocks: along `axis` (mode 0: an orthographic camera, a directional light), or
// from the point `axis` through each block's centre (mode 1: a perspective eye, a point or spot light).
struct ImpostorAxis {
  int mode = 0;
  glm::vec3 axis{0.f, 0.f, -1.f};
};

// Tiles of res x res texels, tilesX per row, in an atlas of at most kMaxAtlas texels a side: res is
// the requested resolution or less when that many blocks would not fit (0 when not even kMinRes fits).
struct AtlasLayout {
  static constexpr int kMaxAtlas = 2048, kMinRes = 4;
  int res = 0, tilesX = 0, tilesY = 0;
  int width() const { return tilesX * res; }
  int height() const { return tilesY * res; }
};
AtlasLayout atlasLayout(int blocks, int requestedRes);

class ImpostorSet {
public:
  // Allocates every buffer, texture and framebuffer (no drawing). `slices` K in [1, 16].
  // `fourierTerms` M in [1, 7]: the light's transmittance comes from Fourier opacity maps (Blocks.h)
  // in the slice textures instead of K slices; 0: the slices.
  ImpostorSet(const BlockSet& blocks, const AtlasLayout& layout, int slices, int sliceResolution, int fourierTerms = 0);
  // Draws the view impostors, the light impostors and the slices (each block's group from `frame`).
  // `light` null: no shadowed light (the slices stay 1).
  void build(gl::ShaderLibrary& shaders, const ImpostorAxis& view, const ImpostorAxis* light, const SliceFrame& frame);
  bool built = false;

  const BlockSet& blocks() const { return blocks_; }
  const AtlasLayout& layout() const { return layout_; }
  int slices() const { return slices_; }
  int fourierTerms() const { return fourierTerms_; }
  // Channels of the slice textures in use: K slices, or the 2M + 1 Fourier coefficients.
  int channels() const { return fourierTerms_ > 0 ? fourierChannels(fourierTerms_) : slices_; }
  int sliceResolution() const { return sliceRes_; }
  const SliceFrame& frame() const { return frame_; }
  const std::vector<gpu::ImpostorBlock>& gpuBlocks() const { return gpuBlocks_; }

  // Channel k (slice k, or Fourier coefficient k) at texel (x, y) is out[(k * res + y) * res + x]
  // (channels() of them; GL rows, bottom first).
  std::vector<float> downloadSlices() const;
  // The view atlas: front, back and transmittance, each width() x height() (GL rows).
  void downloadView(std::vector<float>& front, std::vector<float>& back, std::vector<float>& transmittance) const;

  gl::Buffer particleBuffer, blockBuffer, orderBuffer;
  gl::Texture front, back, transmittance, lightTransmittance;
  gl::Texture lightFront, lightBack;  // Fourier only: the light impostors' depths (each block's box)
  gl::Texture sliceTextures[4];

private:
  void drawImpostors(gl::ShaderLibrary& shaders, const ImpostorAxis& axis, gl::Framebuffer& fb);
  BlockSet blocks_;
  AtlasLayout layout_;
  int slices_, sliceRes_, fourierTerms_;
  SliceFrame frame_;
  std::vector<gpu::ImpostorBlock> gpuBlocks_;
  gl::Framebuffer viewFb_, lightFb_, sliceFb_;
  gl::VertexArray vao_;
};

}  // namespace radiant::impostors

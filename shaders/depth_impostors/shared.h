// What C++ and GLSL share of depth_impostors: one block of particles and its impostor tile, and
// their storage bindings.
// Same rules as common/shared.h (every struct member a vec4/ivec4/mat4, nothing included, constants
// declared with RADIANT_CONST): GLSL includes it after "common/shared.h"; C++ after
// renderer/frame/GpuTypes.h, inside namespace radiant::gpu (renderer/techniques/depth_impostors/Impostors.h).
#ifndef RADIANT_DEPTH_IMPOSTORS_SHARED_H
#define RADIANT_DEPTH_IMPOSTORS_SHARED_H

// gather.frag reads 8 textures: units 0-5 are its full-screen inputs and slices 0-1, slices 2-3 take
// these (common/shared.h: every sampler of every program has its own unit).
RADIANT_CONST int kUnitImpostorSlices2 = 33;
RADIANT_CONST int kUnitImpostorSlices3 = 34;
RADIANT_CONST int kBindingImpostorBlocks = 4;
RADIANT_CONST int kBindingImpostorOrder = 5;  // int[]: the blocks back to front
RADIANT_CONST int kMaxImpostorSlices = 16;  // K: 4 slices per RGBA texture, at most 4 textures
struct ImpostorBlock {
  vec4 centerRadius;  // xyz world centre, w radius of the sphere bounding its particles
  vec4 source;        // rgb the particles' direction-independent source (tau r^3 weighted), w unused
  vec4 albedoG;       // rgb albedo (tau r^3 weighted), w phase g
  ivec4 info;         // x impostor tile, y phase model (kPhase*), z light group (slice), w particle count
};

#endif

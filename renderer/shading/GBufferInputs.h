#pragma once
// The G-buffer's attachments as the passes that read them see them: typed, so no pass names another's
// resources by string (issue 33). The gbuffer technique writes them (renderer/techniques/gbuffer,
// shaders/gbuffer/gbuffer.frag, in this order); their resource names, the AOV table's (api/Aovs.cpp),
// are written here once.
//
// A program that reads the G-buffer the common way declares each attachment at its unit in
// shaders/common/shared.h (kUnitGbufferPosition ... kUnitGbufferSpecular) and the pass binds them with
// bind(); a program that keeps a low unit for its own input (the denoiser, ambient_occlusion's resolve,
// the media passes) binds an attachment elsewhere with bindAt(). Access is still checked as declared
// (FrameResources' pass scope): an attachment a pass did not declare among its inputs throws.
#include <initializer_list>
#include <iterator>

#include "renderer/frame/FrameResources.h"

namespace radiant::gbuffer {

enum class Attachment {
  Position,         // xyz world position, w linear view depth (0: no surface)
  Normal,           // shading normal
  Albedo,           // base colour
  Material,         // metallic, roughness, occlusion, transmission
  Emission,         // emitted radiance, a = ior
  GeometricNormal,  // geometric normal facing the viewer
  Layers,           // clear coat, coat normal and sheen, packed (common/material.glsl encodeLayers)
  Specular,         // KHR_materials_specular colour and weight
};
inline constexpr Attachment kAttachments[] = {Attachment::Position, Attachment::Normal,   Attachment::Albedo,
                                              Attachment::Material, Attachment::Emission, Attachment::GeometricNormal,
                                              Attachment::Layers,   Attachment::Specular};

// The resource (and AOV) name: "gbuffer_position", "normal", ...
const char* name(Attachment a);
// The unit of shaders/common/shared.h a common program reads it at.
GLuint unit(Attachment a);
// The internal format the gbuffer pass allocates it with.
GLenum format(Attachment a);

gl::Texture& texture(FrameResources& res, Attachment a);
// Whether this frame's G-buffer holds it (a frame without triangles has no G-buffer).
bool written(const FrameResources& res, Attachment a);
// Binds each attachment at unit(a).
void bind(FrameResources& res, std::initializer_list<Attachment> attachments);
// Binds one attachment at another unit.
void bindAt(FrameResources& res, Attachment a, GLuint unit);

}  // namespace radiant::gbuffer

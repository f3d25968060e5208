// beauty += specular (additive blending set by the pass): the traced reflection/refraction radiance
// joins the direct term that the `direct` pass already wrote for the same pixel.
in vec2 v_uv;
layout(binding = 0) uniform sampler2D t_specular;
layout(location = 0) out vec4 o_beauty;
void main() {
  o_beauty = vec4(texelFetch(t_specular, ivec2(gl_FragCoord.xy), 0).rgb, 0.0);
}

// beauty = beauty * T + C (blend ONE, SRC_ALPHA set by the pass): the media layer over the opaque
// image (thesis 7.2.3), for every media technique (the one that owns the media AOV this frame).
in vec2 v_uv;
layout(binding = 0) uniform sampler2D t_media;
layout(location = 0) out vec4 o_beauty;
void main() { o_beauty = texelFetch(t_media, ivec2(gl_FragCoord.xy), 0); }

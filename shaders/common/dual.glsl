// The macros of the files written for both GLSL and C++ (common/brdf.glsl, common/material_decode.glsl;
// the beam.glsl approach). GLSL includes this file from them; C++ includes it as
// "shaders/common/dual.glsl" before the namespace it includes them in (the shader library expands
// #include even inside #ifdef __cplusplus, so a dual file cannot include it in both languages).
//   RADIANT_FN      a function: inline and always inlined in C++ (the path tracer's hot loop)
//   RADIANT_IN(T)   a struct parameter: a const reference in C++, not a copy
//   RADIANT_OUT(T)  an out parameter
#ifndef RADIANT_COMMON_DUAL
#define RADIANT_COMMON_DUAL
#ifdef __cplusplus
#define RADIANT_FN inline __attribute__((always_inline))
#define RADIANT_IN(T) const T&
#define RADIANT_OUT(T) T&
#else
#define RADIANT_FN
#define RADIANT_IN(T) T
#define RADIANT_OUT(T) out T
#endif
#endif

#pragma once
// How a pass composes its result into beauty (TechniqueInfo::beautyBlend, a technique descriptor's
// "beauty_blend"), which orders it among the frame's beauty writers (FramePlanner's executionOrder) and
// is the blend its BeautyWrite applies (renderer/frame/Beauty.h): Add commutes with the other adds (beauty
// starts each frame at zero); Over (blended surfaces: beauty = a Ls + (1 - a) beauty) runs after every add;
// Transmit (media: beauty = beauty T + C) after every add and over.
namespace radiant {

enum class BeautyBlend { Add, Over, Transmit };

inline const char* toString(BeautyBlend b) {
  switch (b) {
    case BeautyBlend::Add: return "add";
    case BeautyBlend::Over: return "over";
    default: return "transmit";
  }
}

}  // namespace radiant

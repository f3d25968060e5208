#pragma once
// Light-path classes: which light a technique supplies, in Heckbert's regular expressions over L (a
// light; L(point) a punctual one, L(area) an emissive surface, L(sky) the environment), D (diffuse),
// G (glossy), S (specular) and E (the eye); "media" is the participating media's light. A technique
// declares the classes it can supply in its descriptor ("light_paths", "requires_paths"); the planner
// gives each class to one planned technique per frame (renderer/frame/FramePlanner.h, the ownership
// policy), so every light path is counted once. The names are the descriptors' and the stats'
// (`stats.light_paths`); the bits are what a pass tests (FrameResources::owns). A descriptor naming a
// class that is not listed here fails the build (api/tools/merge_schema.cpp), so a misspelt class can
// no longer be a class nobody owns. Header-only: the build-time schema tool includes it too.
#include <array>
#include <cstdint>
#include <string_view>

namespace radiant::api {

using LightPathMask = std::uint32_t;

struct LightPathClass {
  std::string_view name;
  LightPathMask bit;
};

inline constexpr std::array<LightPathClass, 13> kLightPathClasses{{
    {"LE", 1u << 0},           // emission seen by the eye
    {"L(point)DE", 1u << 1},   // punctual lights on a diffuse or glossy surface
    {"L(area)DE", 1u << 2},    // emissive surfaces' direct light
    {"L(sky)DE", 1u << 3},     // the environment's direct light, diffuse lobe
    {"L(sky)GE", 1u << 4},     // the environment's direct light, glossy lobe
    {"LD+DE", 1u << 5},        // indirect diffuse light
    {"LS+DE", 1u << 6},        // caustics through mirrors and smooth glass
    {"LG+DE", 1u << 7},        // light through glossy metal or glass onto a diffuse surface
    {"LS+E", 1u << 8},         // lights seen in mirrors
    {"LDS+E", 1u << 9},        // directly lit surfaces seen in mirrors
    {"LD+DS+E", 1u << 10},     // indirectly lit surfaces seen in mirrors
    {"LS+DS+E", 1u << 11},     // caustics seen in mirrors
    {"media", 1u << 12},       // participating media
}};

// The class's bit; 0 for a name that is not a class.
constexpr LightPathMask lightPathBit(std::string_view name) {
  for (const LightPathClass& c : kLightPathClasses)
    if (c.name == name) return c.bit;
  return 0;
}

// The class of a bit (one bit set); empty for anything else.
constexpr std::string_view lightPathName(LightPathMask bit) {
  for (const LightPathClass& c : kLightPathClasses)
    if (c.bit == bit) return c.name;
  return {};
}

inline constexpr LightPathMask kPathLE = lightPathBit("LE");
inline constexpr LightPathMask kPathSkyDE = lightPathBit("L(sky)DE");
inline constexpr LightPathMask kPathSkyGE = lightPathBit("L(sky)GE");
inline constexpr LightPathMask kPathLDDE = lightPathBit("LD+DE");
inline constexpr LightPathMask kPathLSDE = lightPathBit("LS+DE");
inline constexpr LightPathMask kPathLGDE = lightPathBit("LG+DE");
inline constexpr LightPathMask kPathLSDSE = lightPathBit("LS+DS+E");
inline constexpr LightPathMask kPathMedia = lightPathBit("media");

}  // namespace radiant::api

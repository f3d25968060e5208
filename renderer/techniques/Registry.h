#pragma once
#include <memory>
#include <vector>

#include "renderer/frame/Technique.h"

namespace radiant {

// Every technique, in the order that breaks the frame graph's ties (Registry.cpp).
std::vector<std::unique_ptr<Technique>> createTechniques();

}  // namespace radiant

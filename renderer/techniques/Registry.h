#pragma once
#include <memory>
#include <vector>

#include "renderer/frame/Technique.h"

namespace radiant {

// Every technique, in canonical execution order (producers before consumers).
std::vector<std::unique_ptr<Technique>> createTechniques();

}  // namespace radiant

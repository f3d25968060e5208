#pragma once
// BackendHooks backed by the real renderer (Renderer, glTF loader, built-in scenes, OpenImageIO).
#include "server/Backend.h"
#include "server/Config.h"

namespace radiant::server {

BackendHooks rendererHooks(const ServerConfig& config);

}  // namespace radiant::server

#pragma once
// A technique that declares what the test gives it and draws nothing: the planner's tests (light-path
// ownership, required classes, media ownership) register stand-ins beside real passes. It runs unless
// told not to, then its requirements() skip it with "stand-in skips".
#include <utility>

#include "renderer/frame/Technique.h"

namespace radiant::testing {

class StandInTechnique final : public Technique {
public:
  explicit StandInTechnique(TechniqueInfo info, bool runs = true) : info_(std::move(info)), runs_(runs) {}
  const TechniqueInfo& info() const override { return info_; }
  Requirements requirements(const Scene&, const api::RenderRequest&) const override {
    return runs_ ? Requirements::ok() : Requirements::skip("stand-in skips");
  }
  void prepare(const Scene&, const Params&, FrameResources&) override {}
  void execute(PassContext&) override {}

private:
  TechniqueInfo info_;
  bool runs_;
};

}  // namespace radiant::testing

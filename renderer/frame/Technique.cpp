#include "renderer/frame/Technique.h"

#include "api/Validate.h"

namespace radiant {

TechniqueInfo describedTechnique(std::string_view name) {
  const api::TechniqueSchema* d = api::findTechnique(name);
  if (!d) throw std::logic_error("no descriptor declares the technique '" + std::string(name) + "'");
  TechniqueInfo i;
  i.name = d->name;
  i.description = d->summary;
  i.inputs = d->inputs;
  i.optionalInputs = d->optionalInputs;
  i.prepareOutputs = d->prepareOutputs;
  i.beautyBlend = d->beautyBlend == "over"       ? BeautyBlend::Over
                  : d->beautyBlend == "transmit" ? BeautyBlend::Transmit
                                                 : BeautyBlend::Add;
  i.outputs = d->outputs;
  i.outputs.insert(i.outputs.end(), d->resources.begin(), d->resources.end());
  i.addsToBeauty = d->addsToBeauty;
  i.onByDefault = d->onByDefault;
  i.lightPaths = d->lightPaths;
  i.claimsWhenNamed = d->claimsWhenNamed;
  i.exclusive = d->exclusive;
  i.requiredPaths = d->requiredPaths;
  return i;
}

}  // namespace radiant

#include "trajroi/vlp16/model.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr std::array<ModelSpec, kModelCount> kSpecs{{
    {Model::kVlp16, "VLP-16", "vlp16", 0x22, 16, 1, 2.304, 55.296, 2'304, 55'296, 0.002},
    {Model::kPuckHiRes, "Puck Hi-Res", "puck_hires", 0x24, 16, 1, 2.304, 55.296, 2'304, 55'296, 0.002},
    {Model::kVlp32c, "VLP-32C", "vlp32c", 0x28, 32, 2, 2.304, 55.296, 2'304, 55'296, 0.004},
    {Model::kHdl32e, "HDL-32E", "hdl32e", 0x21, 32, 1, 1.152, 46.08, 1'152, 46'080, 0.002},
}};

}  // namespace

const ModelSpec& spec(Model model) noexcept {
  return kSpecs[static_cast<std::size_t>(model)];
}

std::optional<Model> unambiguous_model(std::uint8_t product_id) noexcept {
  switch (product_id) {
    case 0x22:
      return Model::kVlp16;
    case 0x24:
      return Model::kPuckHiRes;
    case 0x28:
      return Model::kVlp32c;
    default:
      return std::nullopt;
  }
}

std::optional<Model> model_named(std::string_view name) noexcept {
  if (name == "puck_lite") return Model::kVlp16;
  for (const ModelSpec& s : kSpecs)
    if (s.config_name == name) return s.model;
  return std::nullopt;
}

}  // namespace trajroi::vlp16

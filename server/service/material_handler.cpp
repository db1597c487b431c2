#include "service/material_handler.hpp"

#include <algorithm>
#include <cctype>
#include <optional>

#include "service/pressure_fall_message.hpp"

namespace balloon::service {
namespace {

bool is_preset(const std::string& name) {
  const auto names = preset_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

void fill_constants(const Material& material, balloon::v1::Material* reply) {
  reply->set_model(model_name(material.model));
  const auto names = parameter_names(material.model);
  for (std::size_t i = 0; i < names.size(); ++i) (*reply->mutable_params())[names[i]] = material.params[i];
  if (const std::optional<PressureFallBand> band = pressure_fall_band(material))
    fill_pressure_fall(*band, std::nullopt, *reply->mutable_pressure_fall());
}

void fill_preset(const std::string& name, balloon::v1::Material* reply) {
  const Result<Material> material = preset_material(name);
  reply->set_name(name);
  reply->set_preset(true);
  if (!material) return;
  reply->set_spec(material_spec(*material));
  reply->set_description("built-in preset (values and sources in README.md)");
  fill_constants(*material, reply);
}

void fill_stored(const store::MaterialRecord& record, balloon::v1::Material* reply) {
  reply->set_name(record.name);
  reply->set_spec(record.spec);
  reply->set_description(record.description);
  reply->set_created_ms(record.created_ms);
  reply->set_updated_ms(record.updated_ms);
  if (const Result<Material> material = parse_material_spec(record.spec)) fill_constants(*material, reply);
}

}  // namespace

std::string material_name_problem(const std::string& name) {
  if (name.empty()) return "material name is empty";
  if (name.size() > 64) return "material name is longer than 64 characters";
  for (const char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-'))
      return "material name '" + name + "' may only hold letters, digits, '.', '_' and '-'";
  return "";
}

ServiceStatus MaterialHandler::put(const Caller& caller, const balloon::v1::PutMaterialRequest& request,
                                   balloon::v1::Material* reply) {
  const balloon::v1::Material& material = request.material();
  if (const std::string problem = material_name_problem(material.name()); !problem.empty())
    return ServiceStatus::bad_field("material.name", problem);
  if (is_preset(material.name()))
    return ServiceStatus::field_error(StatusCode::PermissionDenied, "material.name",
                                      "'" + material.name() + "' is a built-in preset and cannot be replaced");
  const Result<Material> parsed = parse_material_spec(material.spec());
  if (!parsed) return ServiceStatus::bad_field("material.spec", "spec: " + parsed.error());
  const store::MaterialRecord record =
      m_materials.put(caller.tenant, material.name(), material_spec(*parsed), material.description());
  fill_stored(record, reply);
  return ServiceStatus::success();
}

ServiceStatus MaterialHandler::get(const Caller& caller, const balloon::v1::GetMaterialRequest& request,
                                   balloon::v1::Material* reply) {
  if (is_preset(request.name())) {
    fill_preset(request.name(), reply);
    return ServiceStatus::success();
  }
  const auto record = m_materials.get(caller.tenant, request.name());
  if (!record) return ServiceStatus::error(StatusCode::NotFound, "no material named '" + request.name() + "'");
  fill_stored(*record, reply);
  return ServiceStatus::success();
}

ServiceStatus MaterialHandler::list(const Caller& caller, const balloon::v1::ListMaterialsRequest&,
                                    balloon::v1::ListMaterialsResponse* reply) {
  for (const std::string& name : preset_names()) fill_preset(name, reply->add_materials());
  for (const store::MaterialRecord& record : m_materials.list(caller.tenant)) fill_stored(record, reply->add_materials());
  return ServiceStatus::success();
}

ServiceStatus MaterialHandler::remove(const Caller& caller, const balloon::v1::DeleteMaterialRequest& request,
                                      balloon::v1::DeleteMaterialResponse*) {
  if (is_preset(request.name()))
    return ServiceStatus::error(StatusCode::PermissionDenied,
                                "'" + request.name() + "' is a built-in preset and cannot be deleted");
  if (!m_materials.remove(caller.tenant, request.name()))
    return ServiceStatus::error(StatusCode::NotFound, "no material named '" + request.name() + "'");
  return ServiceStatus::success();
}

Result<Material> MaterialHandler::resolve(const std::string& tenant, const balloon::v1::MaterialRef& reference) {
  switch (reference.kind_case()) {
    case balloon::v1::MaterialRef::kSpec: return parse_material_spec(reference.spec());
    case balloon::v1::MaterialRef::kName: {
      const std::string& name = reference.name();
      if (is_preset(name)) return preset_material(name);
      const auto record = m_materials.get(tenant, name);
      if (!record) {
        std::string presets;
        for (const std::string& preset : preset_names()) presets += (presets.empty() ? "" : ", ") + preset;
        return fail("unknown material '" + name + "' (not a preset: " + presets + "; not a stored material)");
      }
      Result<Material> material = parse_material_spec(record->spec);
      if (material) material->name = name;
      return material;
    }
    case balloon::v1::MaterialRef::KIND_NOT_SET: break;
  }
  return fail("no material given (a name or a SPEC)");
}

}  // namespace balloon::service

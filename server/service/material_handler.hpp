#pragma once
/// Materials: the built-in presets (readable by all, immutable) and each tenant's named materials.
/// Takes and returns API messages; knows nothing of gRPC.
#include "balloon/v1/balloon.pb.h"
#include "material/material.hpp"
#include "result.hpp"
#include "service/caller.hpp"
#include "service/service_status.hpp"
#include "store/material_store.hpp"

namespace balloon::service {

class MaterialHandler {
 public:
  explicit MaterialHandler(store::Store& store) : m_materials(store) {}

  /// Stores or replaces the caller's material. INVALID_ARGUMENT for a bad name or SPEC,
  /// PERMISSION_DENIED for a preset's name.
  ServiceStatus put(const Caller& caller, const balloon::v1::PutMaterialRequest& request, balloon::v1::Material* reply);
  /// A preset or one of the caller's materials; NOT_FOUND otherwise.
  ServiceStatus get(const Caller& caller, const balloon::v1::GetMaterialRequest& request, balloon::v1::Material* reply);
  /// Presets first, then the caller's materials by name.
  ServiceStatus list(const Caller& caller, const balloon::v1::ListMaterialsRequest& request,
                     balloon::v1::ListMaterialsResponse* reply);
  /// PERMISSION_DENIED for a preset, NOT_FOUND if the caller has no such material.
  ServiceStatus remove(const Caller& caller, const balloon::v1::DeleteMaterialRequest& request,
                       balloon::v1::DeleteMaterialResponse* reply);

  /// The material a job names: a preset, the tenant's stored material, or an inline SPEC. The error
  /// names the problem ("unknown material 'x'...").
  Result<Material> resolve(const std::string& tenant, const balloon::v1::MaterialRef& reference);

 private:
  store::MaterialStore m_materials;
};

/// Empty if `name` is a valid material name ([A-Za-z0-9._-], 1-64 characters), else the problem.
std::string material_name_problem(const std::string& name);

}  // namespace balloon::service

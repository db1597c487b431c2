#include "material_argument.hpp"

#include "material/material.hpp"

namespace balloon::cli {

Result<balloon::v1::MaterialRef> material_reference(const std::string& spec) {
  balloon::v1::MaterialRef reference;
  const bool bare_name = spec.find(':') == std::string::npos && !spec.empty();
  const Result<Material> material = parse_material_spec(spec);
  if (!material && !bare_name) return fail("--material: " + material.error());
  // Presets and stored materials travel by name (the report then names them); inline SPECs as given.
  if (bare_name)
    reference.set_name(spec);
  else
    reference.set_spec(spec);
  return reference;
}

}  // namespace balloon::cli

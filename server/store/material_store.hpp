#pragma once
/// Tenants' named materials in the store (presets live in core and are never stored).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "store/store.hpp"

namespace balloon::store {

/// One stored material: SPEC text (moduli MPa) and a description, per owner.
struct MaterialRecord {
  std::string owner;
  std::string name;
  std::string spec;
  std::string description;
  std::int64_t created_ms = 0;
  std::int64_t updated_ms = 0;
};

class MaterialStore {
 public:
  explicit MaterialStore(Store& store) : m_store(store) {}

  /// Inserts or replaces (owner, name); keeps created_ms of a replaced one. Returns the stored record.
  MaterialRecord put(const std::string& owner, const std::string& name, const std::string& spec,
                     const std::string& description);
  std::optional<MaterialRecord> get(const std::string& owner, const std::string& name);
  /// The owner's materials by name.
  std::vector<MaterialRecord> list(const std::string& owner);
  /// False if there was no such material.
  bool remove(const std::string& owner, const std::string& name);

 private:
  Store& m_store;
};

}  // namespace balloon::store

#include "store/material_store.hpp"

namespace balloon::store {
namespace {

constexpr const char* UPSERT_MATERIAL =
    "INSERT INTO materials (owner, name, spec, description, created_ms, updated_ms) VALUES (?, ?, ?, ?, ?, ?) "
    "ON CONFLICT (owner, name) DO UPDATE SET spec = excluded.spec, description = excluded.description, "
    "updated_ms = excluded.updated_ms";
constexpr const char* SELECT_MATERIAL =
    "SELECT owner, name, spec, description, created_ms, updated_ms FROM materials WHERE owner = ? AND name = ?";
constexpr const char* SELECT_MATERIALS =
    "SELECT owner, name, spec, description, created_ms, updated_ms FROM materials WHERE owner = ? ORDER BY name";
constexpr const char* DELETE_MATERIAL = "DELETE FROM materials WHERE owner = ? AND name = ?";

MaterialRecord read_material(const Statement& row) {
  MaterialRecord record;
  record.owner = row.column_text(0);
  record.name = row.column_text(1);
  record.spec = row.column_text(2);
  record.description = row.column_text(3);
  record.created_ms = row.column_int64(4);
  record.updated_ms = row.column_int64(5);
  return record;
}

}  // namespace

MaterialRecord MaterialStore::put(const std::string& owner, const std::string& name, const std::string& spec,
                                  const std::string& description) {
  return m_store.write_durably([&] {
    Transaction transaction(m_store.database());
    const std::int64_t now = now_ms();
    m_store.database()
        .prepare(UPSERT_MATERIAL)
        .bind(1, owner)
        .bind(2, name)
        .bind(3, spec)
        .bind(4, description)
        .bind(5, now)
        .bind(6, now)
        .run();
    MaterialRecord record;
    {
      Statement statement = m_store.database().prepare(SELECT_MATERIAL);
      statement.bind(1, owner).bind(2, name);
      if (!statement.step()) throw DatabaseError("material vanished after insert");
      record = read_material(statement);
    }
    transaction.commit();
    return record;
  });
}

std::optional<MaterialRecord> MaterialStore::get(const std::string& owner, const std::string& name) {
  std::lock_guard lock(m_store.mutex());
  Statement statement = m_store.database().prepare(SELECT_MATERIAL);
  statement.bind(1, owner).bind(2, name);
  if (!statement.step()) return std::nullopt;
  return read_material(statement);
}

std::vector<MaterialRecord> MaterialStore::list(const std::string& owner) {
  std::lock_guard lock(m_store.mutex());
  Statement statement = m_store.database().prepare(SELECT_MATERIALS);
  statement.bind(1, owner);
  std::vector<MaterialRecord> records;
  while (statement.step()) records.push_back(read_material(statement));
  return records;
}

bool MaterialStore::remove(const std::string& owner, const std::string& name) {
  return m_store.write_durably([&] {
    m_store.database().prepare(DELETE_MATERIAL).bind(1, owner).bind(2, name).run();
    return m_store.database().changes() == 1;
  });
}

}  // namespace balloon::store

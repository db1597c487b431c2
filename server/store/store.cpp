#include "store/store.hpp"

#include <chrono>

#include "store/schema.hpp"

namespace balloon::store {

std::int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

Store::Store(const std::string& path) : m_database(path) { migrate(m_database); }

}  // namespace balloon::store

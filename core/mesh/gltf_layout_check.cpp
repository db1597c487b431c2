#include "mesh/gltf_layout_check.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <initializer_list>
#include <limits>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace balloon {

namespace {

using Json = nlohmann::json;

/// An accessor without a buffer view (a sparse one over zeros) is allocated by assimp from its count alone:
/// at most this many bytes, so that a few bytes of JSON cannot ask for gigabytes.
constexpr std::uint64_t MAX_UNBACKED_ACCESSOR_BYTES = std::uint64_t{64} << 20;

constexpr std::uint64_t MAX_U32 = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t MAX_U64 = std::numeric_limits<std::uint64_t>::max();

struct BufferView {
  std::uint64_t length = 0;
  std::uint64_t stride = 0;  ///< 0: tightly packed
};

struct Accessor {
  std::uint64_t component_type = 0;
  std::string type;
  std::uint64_t count = 0;
  std::uint64_t element_size = 0;  ///< bytes
};

/// Bytes of one component of a glTF componentType, 0 for an unknown one.
std::uint64_t component_size(std::uint64_t component_type) {
  switch (component_type) {
    case 5120: case 5121: return 1;  // (unsigned) byte
    case 5122: case 5123: return 2;  // (unsigned) short
    case 5125: case 5126: return 4;  // unsigned int, float
    default: return 0;
  }
}

/// Components of a glTF accessor type, 0 for an unknown one.
std::uint64_t component_count(const std::string& type) {
  for (const auto& [name, count] : {std::pair{"SCALAR", 1}, std::pair{"VEC2", 2}, std::pair{"VEC3", 3},
                                    std::pair{"VEC4", 4}, std::pair{"MAT2", 4}, std::pair{"MAT3", 9},
                                    std::pair{"MAT4", 16}}) {
    if (type == name) return static_cast<std::uint64_t>(count);
  }
  return 0;
}

/// True if `uri` is `data:TYPE;base64,` and strict base64 (length a multiple of 4, `=` only as padding).
/// assimp 5.2 leaks the buffer it decodes when the base64 turns out bad; assimp_reader's scan of the raw text
/// checks the same, but misses a `uri` key spelled with escapes, which only a JSON parser sees.
bool is_strict_base64_data_uri(const std::string& uri) {
  const std::size_t comma = uri.find(',');
  if (comma == std::string::npos || comma < 12 || uri.compare(comma - 7, 7, ";base64") != 0) return false;
  std::string_view payload = std::string_view(uri).substr(comma + 1);
  if (payload.size() % 4 != 0) return false;
  for (int pad = 0; pad < 2 && !payload.empty() && payload.back() == '='; ++pad) payload.remove_suffix(1);
  return payload.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/") ==
         std::string_view::npos;
}

/// "" or why a buffer or image `uri` is a data: URI assimp would mishandle (other URIs are refused by the
/// sealed I/O system, which names them).
std::string check_uri(const Json& object, const std::string& where) {
  const auto uri = object.find("uri");
  if (uri == object.end() || !uri->is_string()) return {};
  const std::string& text = uri->get_ref<const std::string&>();
  if (text.rfind("data:", 0) == 0 && !is_strict_base64_data_uri(text)) {
    return "bad glTF: " + where + ": a data: URI that is not strict base64 (data:TYPE;base64,...)";
  }
  return {};
}

/// "" with `value` set from the member `key` of `object` (left as it is when absent and not `required`), or
/// why not: a value that is not an integer from 0 to `max` is refused rather than ignored as assimp does.
std::string read_uint(const Json& object, const char* key, const std::string& where, std::uint64_t& value,
                      bool required, std::uint64_t max = MAX_U32) {
  const auto it = object.find(key);
  if (it == object.end()) return required ? "bad glTF: " + where + " has no '" + key + "'" : "";
  if (!it->is_number_unsigned() || it->get<std::uint64_t>() > max) {
    return "bad glTF: " + where + ": '" + key + "' is not an integer from 0 to " + std::to_string(max);
  }
  value = it->get<std::uint64_t>();
  return {};
}

/// "" with `items` pointing at the array `key` of `object` (an empty one when absent), or why it is not an array
/// of objects. `what` names one item in messages.
std::string read_objects(const Json& object, const char* key, const char* what, const Json*& items) {
  static const Json none = Json::array();
  const auto it = object.find(key);
  items = &none;
  if (it == object.end()) return {};
  if (!it->is_array()) return std::string("bad glTF: '") + key + "' is not an array";
  for (std::size_t i = 0; i < it->size(); ++i) {
    if (!(*it)[i].is_object()) return std::string("bad glTF: ") + what + " " + std::to_string(i) + " is not an object";
  }
  items = &*it;
  return {};
}

/// "" or why an accessor used as `use` is not one of `types` with one of `components` (the specification's
/// types for that use; assimp copies each element into a fixed-size struct and leaks when one does not fit).
std::string check_use(const std::vector<Accessor>& accessors, std::uint64_t index, const std::string& use,
                      std::initializer_list<const char*> types, std::initializer_list<std::uint64_t> components) {
  const Accessor& a = accessors[index];
  const bool type_ok = std::any_of(types.begin(), types.end(), [&](const char* t) { return a.type == t; });
  const bool component_ok = std::find(components.begin(), components.end(), a.component_type) != components.end();
  if (type_ok && component_ok) return {};
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "..." + std::string chains here.
  std::string allowed;
  for (const char* t : types) {
    if (!allowed.empty()) allowed += '/';
    allowed += t;
  }
  allowed += " of componentType";
  for (const std::uint64_t c : components) {
    allowed += ' ';
    allowed += std::to_string(c);
  }
  return "bad glTF: " + use + " (accessor " + std::to_string(index) + ") must be " + allowed + ", not " + a.type +
         " of " + std::to_string(a.component_type);
}

class LayoutCheck {
 public:
  LayoutCheck(const Json& doc, std::optional<std::uint64_t> glb_bin_length) : m_doc(doc), m_bin(glb_bin_length) {}

  std::string run() {
    if (!m_doc.is_object()) return "bad glTF: the JSON is not an object";
    // Skins and animations are not part of a balloon's shape, and assimp 5.2 reads them without checks
    // (an inverse bind matrix per joint, sampler accessors of any type): refused rather than checked.
    for (const char* unsupported : {"skins", "animations"}) {
      const auto it = m_doc.find(unsupported);
      if (it != m_doc.end() && !(it->is_array() && it->empty())) {
        return std::string("bad glTF: ") + unsupported + " are not supported (an upload is one static mesh)";
      }
    }
    // Draco-compressed primitives go to the Draco decoder linked into Debian's assimp, which our fuzzing
    // never reaches (the seeds have none): refused by name rather than left to an unchecked decoder.
    if (const auto meshes = m_doc.find("meshes"); meshes != m_doc.end() && meshes->is_array()) {
      for (const Json& mesh : *meshes) {
        const auto primitives = mesh.is_object() ? mesh.find("primitives") : mesh.end();
        if (!mesh.is_object() || primitives == mesh.end() || !primitives->is_array()) continue;
        for (const Json& primitive : *primitives) {
          const auto extensions = primitive.is_object() ? primitive.find("extensions") : primitive.end();
          if (primitive.is_object() && extensions != primitive.end() && extensions->is_object() &&
              extensions->contains("KHR_draco_mesh_compression")) {
            return "bad glTF: Draco-compressed meshes (KHR_draco_mesh_compression) are not supported; export without "
                   "compression";
          }
        }
      }
    }
    // In this order: each step reads what the one before it parsed.
    if (std::string problem = check_buffers(); !problem.empty()) return problem;
    if (std::string problem = check_buffer_views(); !problem.empty()) return problem;
    if (std::string problem = check_accessors(); !problem.empty()) return problem;
    return check_meshes();
  }

 private:
  std::string check_buffers() {
    const Json* buffers = nullptr;
    if (std::string problem = read_objects(m_doc, "buffers", "buffer", buffers); !problem.empty()) return problem;
    for (std::size_t i = 0; i < buffers->size(); ++i) {
      const Json& buffer = (*buffers)[i];
      const std::string where = "buffer " + std::to_string(i);
      std::uint64_t length = 0;
      if (std::string problem = read_uint(buffer, "byteLength", where, length, true, MAX_U64); !problem.empty()) {
        return problem;
      }
      // assimp takes a GLB's binary chunk, when it has one, for buffer 0 whatever its JSON says (data: URIs
      // are checked against their length by assimp).
      if (i == 0 && m_bin && *m_bin > 0 && length > *m_bin) {
        return "bad glTF: " + where + " declares " + std::to_string(length) + " bytes but the GLB's binary chunk has " +
               std::to_string(*m_bin);
      }
      if (std::string problem = check_uri(buffer, where); !problem.empty()) return problem;
      m_buffer_lengths.push_back(length);
    }
    const Json* images = nullptr;
    if (std::string problem = read_objects(m_doc, "images", "image", images); !problem.empty()) return problem;
    for (std::size_t i = 0; i < images->size(); ++i) {
      if (std::string problem = check_uri((*images)[i], "image " + std::to_string(i)); !problem.empty()) return problem;
    }
    return {};
  }

  std::string check_buffer_views() {
    const Json* views = nullptr;
    if (std::string problem = read_objects(m_doc, "bufferViews", "buffer view", views); !problem.empty()) return problem;
    for (std::size_t i = 0; i < views->size(); ++i) {
      const Json& view = (*views)[i];
      const std::string where = "buffer view " + std::to_string(i);
      std::uint64_t buffer = 0, offset = 0;
      BufferView parsed;
      for (std::string problem : {read_uint(view, "buffer", where, buffer, true),
                                  read_uint(view, "byteOffset", where, offset, false, MAX_U64),
                                  read_uint(view, "byteLength", where, parsed.length, true, MAX_U64),
                                  read_uint(view, "byteStride", where, parsed.stride, false)}) {
        if (!problem.empty()) return problem;
      }
      if (buffer >= m_buffer_lengths.size()) return "bad glTF: " + where + " names buffer " + std::to_string(buffer) + ", which does not exist";
      const std::uint64_t buffer_length = m_buffer_lengths[buffer];
      if (offset > buffer_length || parsed.length > buffer_length - offset) {
        return "bad glTF: " + where + " (offset " + std::to_string(offset) + ", length " + std::to_string(parsed.length) +
               ") ends past buffer " + std::to_string(buffer) + " (" + std::to_string(buffer_length) + " bytes)";
      }
      if (view.contains("byteStride") && (parsed.stride < 4 || parsed.stride > 252 || parsed.stride % 4 != 0)) {
        return "bad glTF: " + where + ": byteStride " + std::to_string(parsed.stride) + " is not a multiple of 4 from 4 to 252";
      }
      m_views.push_back(parsed);
    }
    return {};
  }

  /// "" or why accessor `where` reads past buffer view `view` from `offset`: `count` elements of `element_size`
  /// bytes `stride` apart must fit (the specification), and so must `count` whole strides (what assimp 5.2
  /// checks before it copies, ignoring the offset; its index reader trusts the first rule).
  std::string check_extent(const std::string& where, std::uint64_t view, std::uint64_t offset, std::uint64_t count,
                           std::uint64_t element_size, std::uint64_t stride) {
    if (view >= m_views.size()) return "bad glTF: " + where + " names buffer view " + std::to_string(view) + ", which does not exist";
    const std::uint64_t length = m_views[view].length;
    // count < 2^32 and stride, element_size <= 252: no product overflows.
    const std::uint64_t span = count == 0 ? 0 : (count - 1) * stride + element_size;
    if (offset > length || span > length - offset || count * stride > length) {
      return "bad glTF: " + where + " (" + std::to_string(count) + " elements of " + std::to_string(element_size) +
             " bytes, " + std::to_string(stride) + " apart, from offset " + std::to_string(offset) +
             ") does not fit in buffer view " + std::to_string(view) + " (" + std::to_string(length) + " bytes)";
    }
    return {};
  }

  std::string check_accessors() {
    const Json* accessors = nullptr;
    if (std::string problem = read_objects(m_doc, "accessors", "accessor", accessors); !problem.empty()) return problem;
    for (std::size_t i = 0; i < accessors->size(); ++i) {
      const Json& accessor = (*accessors)[i];
      const std::string where = "accessor " + std::to_string(i);
      Accessor parsed;
      std::uint64_t offset = 0;
      for (std::string problem : {read_uint(accessor, "componentType", where, parsed.component_type, true),
                                  read_uint(accessor, "count", where, parsed.count, true),
                                  read_uint(accessor, "byteOffset", where, offset, false, MAX_U64)}) {
        if (!problem.empty()) return problem;
      }
      const auto type = accessor.find("type");
      if (type == accessor.end() || !type->is_string() || component_count(type->get<std::string>()) == 0) {
        return "bad glTF: " + where + " has no type SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4";
      }
      parsed.type = type->get<std::string>();
      if (component_size(parsed.component_type) == 0) {
        return "bad glTF: " + where + ": componentType " + std::to_string(parsed.component_type) + " is not one of glTF's";
      }
      if (parsed.count == 0) return "bad glTF: " + where + " has count 0";
      parsed.element_size = component_size(parsed.component_type) * component_count(parsed.type);
      const bool sparse = accessor.contains("sparse");
      if (accessor.contains("bufferView")) {
        std::uint64_t view = 0;
        if (std::string problem = read_uint(accessor, "bufferView", where, view, true); !problem.empty()) return problem;
        if (view >= m_views.size()) return "bad glTF: " + where + " names buffer view " + std::to_string(view) + ", which does not exist";
        const std::uint64_t stride = m_views[view].stride == 0 ? parsed.element_size : m_views[view].stride;
        if (stride < parsed.element_size) {
          return "bad glTF: " + where + ": its elements (" + std::to_string(parsed.element_size) +
                 " bytes) are wider than the byteStride of buffer view " + std::to_string(view);
        }
        if (std::string problem = check_extent(where, view, offset, parsed.count, parsed.element_size, stride);
            !problem.empty()) {
          return problem;
        }
      } else if (!sparse) {
        return "bad glTF: " + where + " has no bufferView (no data)";
      } else if (parsed.count * parsed.element_size > MAX_UNBACKED_ACCESSOR_BYTES) {
        return "bad glTF: " + where + " has no bufferView and would take " + std::to_string(parsed.count * parsed.element_size) +
               " bytes (the limit is " + std::to_string(MAX_UNBACKED_ACCESSOR_BYTES) + ")";
      }
      if (sparse) {
        if (std::string problem = check_sparse(accessor["sparse"], where, parsed); !problem.empty()) return problem;
      }
      m_accessors.push_back(parsed);
    }
    return {};
  }

  /// assimp 5.2 reads a sparse accessor's indices and values without bounds (and dereferences a missing
  /// bufferView): each must be there, of a valid index type, and within its buffer view.
  std::string check_sparse(const Json& sparse, const std::string& accessor_where, const Accessor& accessor) {
    const std::string where = accessor_where + " sparse";
    if (!sparse.is_object()) return "bad glTF: " + where + " is not an object";
    std::uint64_t count = 0;
    if (std::string problem = read_uint(sparse, "count", where, count, true); !problem.empty()) return problem;
    if (count == 0 || count > accessor.count) {
      return "bad glTF: " + where + ": count " + std::to_string(count) + " is not from 1 to the accessor's " +
             std::to_string(accessor.count);
    }
    for (const char* part : {"indices", "values"}) {
      const std::string part_where = where + " " + part;
      const auto it = sparse.find(part);
      if (it == sparse.end() || !it->is_object()) return "bad glTF: " + part_where + " is missing or not an object";
      std::uint64_t view = 0, offset = 0, component_type = 0;
      for (std::string problem : {read_uint(*it, "bufferView", part_where, view, true),
                                  read_uint(*it, "byteOffset", part_where, offset, false, MAX_U64)}) {
        if (!problem.empty()) return problem;
      }
      std::uint64_t element_size = accessor.element_size;
      if (std::string_view(part) == "indices") {
        if (std::string problem = read_uint(*it, "componentType", part_where, component_type, true); !problem.empty()) {
          return problem;
        }
        if (component_type != 5121 && component_type != 5123 && component_type != 5125) {
          return "bad glTF: " + part_where + ": componentType " + std::to_string(component_type) +
                 " is not an unsigned integer type (5121, 5123 or 5125)";
        }
        element_size = component_size(component_type);
      }
      // Read tightly packed whatever the view's stride (as assimp does).
      if (std::string problem = check_extent(part_where, view, offset, count, element_size, element_size); !problem.empty()) {
        return problem;
      }
    }
    return {};
  }

  /// "" with `index` read from `object[key]` and naming an accessor, or why not.
  std::string read_accessor(const Json& object, const char* key, const std::string& where, std::uint64_t& index,
                            bool required) {
    if (std::string problem = read_uint(object, key, where, index, required); !problem.empty()) return problem;
    if (object.contains(key) && index >= m_accessors.size()) {
      return "bad glTF: " + where + ": '" + key + "' names accessor " + std::to_string(index) + ", which does not exist";
    }
    return {};
  }

  /// "" or why the attributes of a primitive or a morph target are not accessors of their specified types.
  std::string check_attributes(const Json& attributes, const std::string& where, bool target) {
    if (!attributes.is_object()) return "bad glTF: " + where + " is not an object";
    for (const auto& [name, value] : attributes.items()) {
      std::uint64_t index = 0;
      const std::string use = where + " " + name;
      if (std::string problem = read_accessor(attributes, name.c_str(), use, index, true); !problem.empty()) return problem;
      // assimp files attributes by prefix (POSITION, NORMAL, TEXCOORD_n, ...), so the checks go by prefix too.
      const auto starts = [&name = name](const char* prefix) { return name.rfind(prefix, 0) == 0; };
      std::string problem;
      if (starts("POSITION") || starts("NORMAL") || (target && starts("TANGENT"))) {
        problem = check_use(m_accessors, index, use, {"VEC3"}, {5126});
      } else if (starts("TANGENT")) {
        problem = check_use(m_accessors, index, use, {"VEC4"}, {5126});
      } else if (starts("TEXCOORD")) {
        problem = check_use(m_accessors, index, use, {"VEC2"}, {5126, 5121, 5123});
      } else if (starts("COLOR")) {
        problem = check_use(m_accessors, index, use, {"VEC3", "VEC4"}, {5126, 5121, 5123});
      } else if (starts("JOINTS")) {
        problem = check_use(m_accessors, index, use, {"VEC4"}, {5121, 5123});
      } else if (starts("WEIGHTS")) {
        problem = check_use(m_accessors, index, use, {"VEC4"}, {5126, 5121, 5123});
      }
      if (!problem.empty()) return problem;
    }
    return {};
  }

  std::string check_meshes() {
    const Json* meshes = nullptr;
    if (std::string problem = read_objects(m_doc, "meshes", "mesh", meshes); !problem.empty()) return problem;
    for (std::size_t m = 0; m < meshes->size(); ++m) {
      const Json* primitives = nullptr;
      if (std::string problem = read_objects((*meshes)[m], "primitives", "primitive", primitives); !problem.empty()) {
        return problem;
      }
      for (std::size_t p = 0; p < primitives->size(); ++p) {
        if (std::string problem = check_primitive((*primitives)[p], "mesh " + std::to_string(m) + " primitive " + std::to_string(p));
            !problem.empty()) {
          return problem;
        }
      }
    }
    return {};
  }

  std::string check_primitive(const Json& primitive, const std::string& where) {
    const auto attributes = primitive.find("attributes");
    if (attributes == primitive.end()) return "bad glTF: " + where + " has no attributes";
    if (std::string problem = check_attributes(*attributes, where, false); !problem.empty()) return problem;
    std::uint64_t position = 0, indices = 0, mode = 4;
    if (!attributes->contains("POSITION")) return "bad glTF: " + where + " has no POSITION";
    for (std::string problem : {read_accessor(*attributes, "POSITION", where, position, true),
                                read_accessor(primitive, "indices", where, indices, false),
                                read_uint(primitive, "mode", where, mode, false)}) {
      if (!problem.empty()) return problem;
    }
    if (mode > 6) return "bad glTF: " + where + ": mode " + std::to_string(mode) + " is not from 0 to 6";
    const bool indexed = primitive.contains("indices");
    // assimp 5.2 builds each face of an indexed line loop, line strip or triangle fan from the face before
    // it, and a face it skipped (an index past the vertices) has no indices: a null dereference (SEGV,
    // found by fuzz_mesh_glb). Triangles, strips, lines and points skip such faces safely.
    if (indexed && (mode == 2 || mode == 3 || mode == 6)) {
      static constexpr const char* NAMES[] = {"", "", "LINE_LOOP", "LINE_STRIP", "", "", "TRIANGLE_FAN"};
      return "bad glTF: " + where + ": indexed " + NAMES[mode] + " primitives (mode " + std::to_string(mode) +
             ") are not supported; use TRIANGLES";
    }
    if (indexed) {
      if (std::string problem = check_use(m_accessors, indices, where + " indices", {"SCALAR"}, {5121, 5123, 5125});
          !problem.empty()) {
        return problem;
      }
    }
    // Fewer indices (or vertices) than one primitive of the mode: assimp 5.2 reads the first primitive's
    // indices before its loop over the rest, so the count is checked here rather than trusted.
    const std::uint64_t count = m_accessors[indexed ? indices : position].count;
    static constexpr std::uint64_t MINIMUM[] = {1, 2, 2, 2, 3, 3, 3};  // points, lines, loop, strip, triangles, strip, fan
    if (count < MINIMUM[mode]) {
      return "bad glTF: " + where + " has " + std::to_string(count) + (indexed ? " indices" : " vertices") +
             ", fewer than one primitive of mode " + std::to_string(mode) + " needs";
    }
    if (primitive.contains("targets")) {
      const Json* targets = nullptr;
      if (std::string problem = read_objects(primitive, "targets", "morph target", targets); !problem.empty()) return problem;
      for (std::size_t t = 0; t < targets->size(); ++t) {
        if (std::string problem = check_attributes((*targets)[t], where + " target " + std::to_string(t), true); !problem.empty()) {
          return problem;
        }
      }
    }
    return {};
  }

  const Json& m_doc;
  std::optional<std::uint64_t> m_bin;
  std::vector<std::uint64_t> m_buffer_lengths;
  std::vector<BufferView> m_views;
  std::vector<Accessor> m_accessors;
};

}  // namespace

std::string check_gltf_layout(std::string_view json, std::optional<std::uint64_t> glb_bin_length) {
  // A repeated key is refused: assimp's parser takes the first, this one the last, so the two would disagree.
  std::vector<std::set<std::string>> open_objects;
  std::string repeated;
  const Json::parser_callback_t watch_keys = [&](int /*depth*/, Json::parse_event_t event, Json& parsed) {
    if (event == Json::parse_event_t::object_start) {
      open_objects.emplace_back();
    } else if (event == Json::parse_event_t::object_end && !open_objects.empty()) {
      open_objects.pop_back();
    } else if (event == Json::parse_event_t::key && !open_objects.empty() && parsed.is_string() &&
               !open_objects.back().insert(parsed.get<std::string>()).second && repeated.empty()) {
      repeated = parsed.get<std::string>();
    }
    return true;
  };
  Json doc;
  try {
    doc = Json::parse(json.begin(), json.end(), watch_keys);
  } catch (const Json::parse_error& error) {
    return "parse error: the glTF JSON is not valid JSON (at byte " + std::to_string(error.byte) + ")";
  } catch (const Json::exception&) {
    return "parse error: the glTF JSON is not valid JSON";
  }
  if (!repeated.empty()) {
    std::string shown;
    for (const char c : repeated.substr(0, 40)) shown += static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f ? '?' : c;
    return "bad glTF: the key '" + shown + (repeated.size() > 40 ? "...'" : "'") + " is repeated in one object";
  }
  return LayoutCheck(doc, glb_bin_length).run();
}

}  // namespace balloon

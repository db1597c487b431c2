#pragma once
/// The glTF 2.0 rules on buffers, buffer views, accessors and mesh primitives that assimp 5.2 relies on
/// without checking them: breaking one made its importer read out of bounds or leak (tests/fuzz/README.md).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace balloon {

/// "" or why the glTF JSON text `json` is refused: it does not parse, repeats a key in an object, or
/// breaks one of the layout rules of the glTF 2.0 specification that assimp 5.2 does not check before it
/// reads or allocates: every buffer view within its buffer; every accessor of a known type, with data,
/// and within its buffer view for `count` elements at the view's stride (and for `count` whole strides,
/// which assimp reads); sparse indices and values within their views; attribute, index and animation
/// accessors of the types the specification gives them; each primitive a known mode with a POSITION
/// and enough indices (or vertices) for one primitive of that mode; no skins or animations.
/// `glb_bin_length` is the length of a GLB's binary chunk (0 if it has none), which assimp takes for
/// buffer 0 and which must hold the length that buffer declares; for a .gltf it is empty. The nesting of `json` must already be bounded (check_json_depth).
std::string check_gltf_layout(std::string_view json, std::optional<std::uint64_t> glb_bin_length);

}  // namespace balloon

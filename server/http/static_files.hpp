#pragma once
/// The web root side of the gateway: which file a URL path names, and how to label it.
#include <string>

namespace balloon::http {

/// Where a URL path leads under the web root.
struct StaticLookup {
  int http_status = 200;  ///< 200 found; 400 a path that tries to leave the root; 404 nothing there
  std::string file;       ///< the file to send (200 only)
  std::string message;    ///< plain-text reason (400 and 404)
};

/// Resolves `url_path` (percent-decoded, starting with '/') under `web_root`: "/" and directories mean
/// their index.html. Segments "..", backslashes and NUL bytes are refused (400) before the file system
/// is touched, so no path leaves the root. A missing web root gives a 404 that says the page was not built.
StaticLookup find_static_file(const std::string& web_root, const std::string& url_path);

/// Content-Type by extension: .html .js .mjs .css .svg .json .png .jpg .ico .wasm .map .txt .obj .off
/// .stl .ply .glb .gltf .csv; application/octet-stream otherwise.
std::string content_type_for(const std::string& file);

}  // namespace balloon::http

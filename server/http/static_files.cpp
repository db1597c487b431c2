#include "http/static_files.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>

namespace balloon::http {

StaticLookup find_static_file(const std::string& web_root, const std::string& url_path) {
  namespace fs = std::filesystem;
  StaticLookup lookup;
  if (url_path.empty() || url_path.front() != '/' || url_path.find('\\') != std::string::npos ||
      url_path.find('\0') != std::string::npos) {
    lookup.http_status = 400;
    lookup.message = "invalid path";
    return lookup;
  }
  fs::path relative;
  size_t begin = 1;
  while (begin <= url_path.size()) {
    size_t end = url_path.find('/', begin);
    if (end == std::string::npos) end = url_path.size();
    const std::string segment = url_path.substr(begin, end - begin);
    if (segment == "..") {
      lookup.http_status = 400;
      lookup.message = "invalid path: '..' is not allowed";
      return lookup;
    }
    if (!segment.empty() && segment != ".") relative /= segment;
    begin = end + 1;
  }
  std::error_code error;
  if (!fs::is_directory(web_root, error)) {
    lookup.http_status = 404;
    lookup.message = "The web page was not built: there is no directory '" + web_root +
                     "'. Build it with CMake (it builds client/web into <build>/client/web/dist) or start "
                     "balloon-server with --web-root DIR. The JSON API under /api/v1 works without it.\n";
    return lookup;
  }
  fs::path file = fs::path(web_root) / relative;
  if (fs::is_directory(file, error)) file /= "index.html";
  if (!fs::is_regular_file(file, error)) {
    lookup.http_status = 404;
    lookup.message = "not found: " + url_path + "\n";
    return lookup;
  }
  lookup.file = file.string();
  return lookup;
}

std::string content_type_for(const std::string& file) {
  static const std::map<std::string, std::string> types = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".svg", "image/svg+xml"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".ico", "image/x-icon"},
      {".wasm", "application/wasm"},
      {".txt", "text/plain; charset=utf-8"},
      {".csv", "text/csv; charset=utf-8"},
      {".obj", "model/obj"},
      {".off", "text/plain; charset=utf-8"},  // OFF has no registered media type
      {".stl", "model/stl"},
      {".ply", "application/octet-stream"},
      {".glb", "model/gltf-binary"},
      {".gltf", "model/gltf+json"},
  };
  std::string extension = std::filesystem::path(file).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const auto found = types.find(extension);
  return found == types.end() ? "application/octet-stream" : found->second;
}

}  // namespace balloon::http

#include "cli_output.hpp"

#include <google/protobuf/util/json_util.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "mesh/mesh_io.hpp"

namespace balloon::cli {

int report_error(const std::string& command, const std::string& message, int exit_code) {
  std::string line = message;
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  const std::string prefix = command.empty() ? "balloon" : "balloon " + command;
  std::fprintf(stderr, "%s: error: %s\n", prefix.c_str(), line.c_str());
  return exit_code;
}

std::string mesh_output_problem(const std::string& path) {
  const std::filesystem::path file(path);
  const std::string extension = file.extension().string();
  if (extension.empty() || !is_writable_mesh_format(extension))
    return "'" + path + "' must end in .obj, .stl or .ply";
  const std::filesystem::path directory = file.has_parent_path() ? file.parent_path() : ".";
  std::error_code error;
  if (!std::filesystem::is_directory(directory, error)) return "directory '" + directory.string() + "' does not exist";
  return "";
}

Result<bool> write_mesh_file(const TriMesh& mesh, const std::string& path) { return write_mesh(mesh, path); }

Result<bool> write_file_atomically(const std::string& path, const std::string& bytes) {
  const std::filesystem::path target(path);
  // Built by appends: GCC 12 warns falsely (-Wrestrict) on `"." + std::string` here.
  std::string temporary_name(".");
  temporary_name.append(target.filename().string()).append(".tmp").append(std::to_string(::getpid()));
  const std::filesystem::path temporary = target.parent_path() / temporary_name;
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) return fail("cannot write '" + path + "'");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      out.close();
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      return fail("cannot write '" + path + "' (disk full?)");
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, target, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return fail("cannot write '" + path + "': " + error.message());
  }
  return true;
}

std::string message_to_json(const google::protobuf::Message& message) {
  std::string json;
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

std::string format(const char* pattern, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), pattern, value);
  return buffer;
}

std::string saddle_note(int unstable_modes) {
  return "a saddle under volume control: " + std::to_string(unstable_modes) +
         " unstable direction(s) (wrinkling or symmetry breaking; the real balloon may take another shape)";
}

}  // namespace balloon::cli

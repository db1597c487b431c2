// `balloon mesh sphere` checked from outside.
#include <gtest/gtest.h>

#include <filesystem>

#include "cli_test_support.hpp"
#include "mesh/mesh_io.hpp"

namespace balloon::testing {
namespace {

TEST(MeshCommand, WritesAnIcosphereOfTheStatedSize) {
  ScratchDir scratch;
  for (const char* extension : {"obj", "stl", "ply"}) {
    const std::string out = scratch.file(std::string("sphere.") + extension);
    const ProcessResult result =
        run_balloon(scratch, {"mesh", "sphere", "--radius", "12.5", "--subdivisions", "2", "--out", out, "--json"});
    ASSERT_EQ(result.exit_code, 0) << result.err;
    EXPECT_EQ(json_number_field(result.out, "vertices"), 162);
    EXPECT_EQ(json_number_field(result.out, "faces"), 320);
    Result<TriMesh> mesh = read_mesh(out);
    ASSERT_TRUE(mesh.ok()) << mesh.error();
    ASSERT_EQ(mesh->vertex_count(), 162) << extension;
    // Every vertex on the sphere (STL/PLY through float32: 1e-5 relative).
    for (int v = 0; v < mesh->vertex_count(); ++v) EXPECT_NEAR(mesh->vertices.row(v).norm(), 12.5, 12.5 * 1e-5);
  }
}

TEST(MeshCommand, RejectsBadArguments) {
  ScratchDir scratch;
  const std::string out = scratch.file("s.obj");
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"mesh", "sphere", "--radius", "-1", "--subdivisions", "2", "--out", out},
           {"mesh", "sphere", "--radius", "1e300", "--subdivisions", "2", "--out", out},  // beyond any mesh's size limit
           {"mesh", "sphere", "--radius", "1", "--subdivisions", "9", "--out", out},
           {"mesh", "sphere", "--radius", "1", "--subdivisions", "1.5", "--out", out},
           {"mesh", "sphere", "--radius", "1", "--subdivisions", "2"},
           {"mesh", "cube", "--radius", "1", "--subdivisions", "2", "--out", out},
           {"mesh", "sphere", "--radius", "1", "--subdivisions", "2", "--out", scratch.file("s.txt")},
       }) {
    const ProcessResult result = run_balloon(scratch, args);
    EXPECT_EQ(result.exit_code, 2) << args[3];
    EXPECT_EQ(split_lines(result.err).size(), 1u) << result.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

}  // namespace
}  // namespace balloon::testing

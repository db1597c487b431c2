#include "mesh/mesh_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/mesh/mesh_test_helpers.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

using test::offset_icosphere;
using test::same_geometry;
using test::sample_mesh;
using test::TemporaryDirectory;

void expect_contains(const std::string& message, std::initializer_list<std::string> fragments) {
  for (const auto& fragment : fragments) {
    EXPECT_NE(message.find(fragment), std::string::npos) << "message '" << message << "' lacks '" << fragment << "'";
  }
  EXPECT_EQ(message.find('\n'), std::string::npos) << "message spans lines: " << message;
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

// ------------------------------------------------------------------------------------------------
// Fixture writers for formats we read but do not write.

std::string base64(const std::string& bytes) {
  static const char* const alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t chunk = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) chunk |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) chunk |= static_cast<unsigned char>(bytes[i + 2]);
    out += alphabet[(chunk >> 18) & 63];
    out += alphabet[(chunk >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(chunk >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[chunk & 63] : '=';
  }
  return out;
}

/// Float positions then uint32 indices, little-endian, as one glTF buffer.
std::string gltf_buffer(const TriMesh& mesh) {
  std::string bytes;
  auto append = [&bytes](const void* data, std::size_t size) {
    bytes.append(static_cast<const char*>(data), size);
  };
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) {
      const auto value = static_cast<float>(mesh.vertices(v, k));
      append(&value, 4);
    }
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const auto index = static_cast<std::uint32_t>(mesh.faces(f, k));
      append(&index, 4);
    }
  }
  return bytes;
}

/// A glTF 2.0 document with one mesh instanced by `nodes_json` (a JSON array of nodes, all listed in
/// the scene). `buffer_uri` empty means a GLB's binary chunk.
std::string gltf_json(const TriMesh& mesh, const std::string& nodes_json, int node_count,
                      const std::string& buffer_uri) {
  const std::size_t positions_bytes = static_cast<std::size_t>(mesh.vertex_count()) * 12;
  const std::size_t indices_bytes = static_cast<std::size_t>(mesh.face_count()) * 12;
  const Eigen::RowVector3f lo = mesh.vertices.colwise().minCoeff().cast<float>();
  const Eigen::RowVector3f hi = mesh.vertices.colwise().maxCoeff().cast<float>();
  // A stream rather than operator+ chains: GCC 12 warns falsely (-Wrestrict) on "..." + std::string.
  std::ostringstream json;
  json.precision(9);
  json << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[)";
  for (int i = 0; i < node_count; ++i) json << (i ? "," : "") << i;
  json << R"(]}],"nodes":)" << nodes_json
       << R"(,"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":4}]}],)"
       << R"("buffers":[{"byteLength":)" << positions_bytes + indices_bytes;
  if (!buffer_uri.empty()) json << R"(,"uri":")" << buffer_uri << '"';
  json << R"(}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << positions_bytes
       << R"(,"target":34962},{"buffer":0,"byteOffset":)" << positions_bytes << R"(,"byteLength":)"
       << indices_bytes << R"(,"target":34963}],)"
       << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << mesh.vertex_count()
       << R"(,"type":"VEC3","min":[)" << lo(0) << ',' << lo(1) << ',' << lo(2) << R"(],"max":[)" << hi(0)
       << ',' << hi(1) << ',' << hi(2) << R"(]},{"bufferView":1,"componentType":5125,"count":)"
       << 3 * mesh.face_count() << R"(,"type":"SCALAR"}]})";
  return json.str();
}

std::string gltf_embedded(const TriMesh& mesh, const std::string& nodes_json, int node_count) {
  return gltf_json(mesh, nodes_json, node_count,
                   "data:application/octet-stream;base64," + base64(gltf_buffer(mesh)));
}

std::string glb(const TriMesh& mesh, const std::string& nodes_json, int node_count) {
  std::string json = gltf_json(mesh, nodes_json, node_count, "");
  std::string bin = gltf_buffer(mesh);
  json.resize((json.size() + 3) / 4 * 4, ' ');
  bin.resize((bin.size() + 3) / 4 * 4, '\0');
  std::string out;
  auto u32 = [&out](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  out += "glTF";
  u32(2);
  u32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  u32(static_cast<std::uint32_t>(json.size()));
  out += "JSON";
  out += json;
  u32(static_cast<std::uint32_t>(bin.size()));
  out += std::string("BIN\0", 4);
  out += bin;
  return out;
}

std::string ascii_stl(const TriMesh& mesh) {
  std::string out = "solid fixture\n";
  for (int f = 0; f < mesh.face_count(); ++f) {
    out += " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto p = mesh.vertices.row(mesh.faces(f, k)).cast<float>();
      char line[128];
      std::snprintf(line, sizeof line, "   vertex %.9g %.9g %.9g\n", p(0), p(1), p(2));
      out += line;
    }
    out += "  endloop\n endfacet\n";
  }
  return out + "endsolid fixture\n";
}

std::string ascii_ply(const TriMesh& mesh, int quad_face = -1) {
  std::string out = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(mesh.vertex_count()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(mesh.face_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  char line[128];
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", mesh.vertices(v, 0), mesh.vertices(v, 1),
                  mesh.vertices(v, 2));
    out += line;
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    if (f == quad_face) {
      out += "4 " + std::to_string(mesh.faces(f, 0)) + " " + std::to_string(mesh.faces(f, 1)) + " " +
             std::to_string(mesh.faces(f, 2)) + " " + std::to_string(mesh.faces((f + 1) % mesh.face_count(), 0)) + "\n";
    } else {
      out += "3 " + std::to_string(mesh.faces(f, 0)) + " " + std::to_string(mesh.faces(f, 1)) + " " +
             std::to_string(mesh.faces(f, 2)) + "\n";
    }
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// Sample meshes.

struct SampleMesh {
  const char* name;
  int vertices;
  int faces;
};

// Counts from tests/data/meshes/PROVENANCE.md.
const SampleMesh SAMPLE_MESHES[] = {
    {"stanford_bunny_1839.obj", 1839, 3674}, {"teddy_bear.off", 13826, 27648},
    {"hand_fist.off", 1197, 2390},           {"cube_866.off", 866, 1728},
    {"retinal_bumpy_blob.off", 3643, 7282},  {"icosphere_812.off", 812, 1620},
    {"spot.obj", 2930, 5856}};

TEST(MeshIo, EverySampleMeshLoadsAndValidates) {
  for (const SampleMesh& sample : SAMPLE_MESHES) {
    SCOPED_TRACE(sample.name);
    auto mesh = read_mesh(sample_mesh(sample.name));
    ASSERT_TRUE(mesh.ok()) << mesh.error();
    EXPECT_EQ(mesh->vertex_count(), sample.vertices);
    EXPECT_EQ(mesh->face_count(), sample.faces);
    const TriMesh before = *mesh;
    const auto report = validate_balloon_mesh(*mesh);
    ASSERT_TRUE(report.ok()) << report.error();
    EXPECT_FALSE(report->flipped);  // all are oriented outwards
    EXPECT_EQ(report->removed_unreferenced_vertices, 0);
    EXPECT_EQ(report->vertices, sample.vertices);
    EXPECT_EQ(report->faces, sample.faces);
    EXPECT_EQ(report->genus, 0);
    EXPECT_GT(report->volume_mm3, 0.0);
    EXPECT_EQ(mesh->vertices, before.vertices);
    EXPECT_EQ(mesh->faces, before.faces);
  }
}

TEST(MeshIo, ObjKeepsFileOrderAndDigits) {
  // spot.obj: first line "v 0.348799 -0.334989 -0.0832331", first face "f 739/1 735/2 736/3".
  const auto spot = read_mesh(sample_mesh("spot.obj"));
  ASSERT_TRUE(spot.ok()) << spot.error();
  EXPECT_EQ(spot->vertices.row(0), Eigen::RowVector3d(0.348799, -0.334989, -0.0832331));
  EXPECT_EQ(spot->faces.row(0), Eigen::RowVector3i(738, 734, 735));
}

TEST(MeshIo, OffKeepsDoublePrecision) {
  // icosphere_812.off: first vertex "-0.52573111211913348 0.85065080835203999 -2.5720446970240305e-18".
  const auto sphere = read_mesh(sample_mesh("icosphere_812.off"));
  ASSERT_TRUE(sphere.ok()) << sphere.error();
  EXPECT_EQ(sphere->vertices(0, 0), -0.52573111211913348);
  EXPECT_EQ(sphere->vertices(0, 2), -2.5720446970240305e-18);
}

TEST(MeshIo, ObjVariantsParse) {
  // Negative (relative) references, v/vt/vn forms, comments, CRLF, tabs, ignored statements.
  const std::string obj =
      "# tetrahedron\r\nmtllib x.mtl\r\nv 0 0 0\r\nv 1 0 0\r\nv\t0 1 0\r\nv 0 0 1 1.0\r\nvt 0 0\r\nvn 0 0 1\r\n"
      "o thing\r\ng group\r\ns off\r\nusemtl m\r\nf 1 3 2\r\nf 1//1 2//1 4//1\r\nf 2/1/1 3/1/1 4/1/1\r\n"
      "f -4 -1 -2 # last\r\nl 1 2\r\n";
  auto mesh = read_mesh_from_memory(obj, "OBJ");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  ASSERT_EQ(mesh->vertex_count(), 4);
  ASSERT_EQ(mesh->face_count(), 4);
  EXPECT_EQ(mesh->faces.row(3), Eigen::RowVector3i(0, 3, 2));
  const auto report = validate_balloon_mesh(*mesh);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_FALSE(report->flipped);
  EXPECT_NEAR(report->volume_mm3, 1.0 / 6.0, 1e-15);
}

TEST(MeshIo, RoundTripsThroughObjStlAndPly) {
  const TriMesh original = offset_icosphere(2);
  TemporaryDirectory dir;
  for (const char* format : {"obj", "stl", "ply"}) {
    SCOPED_TRACE(format);
    const std::string path = dir.file(std::string("sphere.") + format);
    const auto written = write_mesh(original, path);
    ASSERT_TRUE(written.ok()) << written.error();
    const auto back = read_mesh(path);
    ASSERT_TRUE(back.ok()) << back.error();
    // The STL is a soup of 3 * 320 corners; welding must give back the 162 shared vertices.
    EXPECT_TRUE(same_geometry(original, *back, 1e-6));
    EXPECT_NEAR(enclosed_volume(back->vertices, back->faces) / enclosed_volume(original.vertices, original.faces),
                1.0, 1e-6);
    if (std::string(format) != "stl") {  // indexed formats keep the vertex order
      EXPECT_EQ(back->faces, original.faces);
      EXPECT_LT((back->vertices - original.vertices).cwiseAbs().maxCoeff(), 1e-6 * 50.0);
    }
    TriMesh copy = *back;
    const auto report = validate_balloon_mesh(copy);
    ASSERT_TRUE(report.ok()) << report.error();
    EXPECT_FALSE(report->flipped);
    EXPECT_EQ(report->vertices, 162);
    EXPECT_EQ(dir.entry_count(), 1) << "temporary file left behind";
    std::filesystem::remove(path);
  }
}

TEST(MeshIo, StlWeldingGivesAClosedMesh) {
  const TriMesh original = make_icosphere(10.0, 3);
  auto soup = read_mesh_from_memory(write_mesh_to_memory(original, "stl"), "stl");
  ASSERT_TRUE(soup.ok()) << soup.error();
  EXPECT_EQ(soup->vertex_count(), 642);
  EXPECT_EQ(soup->face_count(), 1280);
  const auto report = validate_balloon_mesh(*soup);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_EQ(report->edges, 1920);
}

TEST(MeshIo, WritingIsDeterministicAndObjUsesNineDigits) {
  const TriMesh mesh = offset_icosphere(1);
  for (const char* format : {"obj", "stl", "ply"}) {
    EXPECT_EQ(write_mesh_to_memory(mesh, format), write_mesh_to_memory(mesh, format)) << format;
  }
  TriMesh one;
  one.vertices.resize(3, 3);
  one.vertices << 1.0 / 3.0, 0, 0, 0, 1, 0, 0, 0, 12345.678901234;
  one.faces.resize(1, 3);
  one.faces << 0, 1, 2;
  const std::string obj = write_mesh_to_memory(one, "obj");
  EXPECT_NE(obj.find("v 0.333333333 0 0\n"), std::string::npos) << obj;
  EXPECT_NE(obj.find("v 0 0 12345.6789\n"), std::string::npos) << obj;
  EXPECT_NE(obj.find("f 1 2 3\n"), std::string::npos) << obj;
  const std::string stl = write_mesh_to_memory(one, "stl");
  EXPECT_EQ(stl.size(), 80u + 4u + 50u);
  EXPECT_NE(stl.substr(0, 5), "solid");
}

TEST(MeshIo, ReadsAsciiStlWithUpperCaseExtension) {
  const TriMesh original = offset_icosphere(1);
  const std::string text = ascii_stl(original);
  auto from_memory = read_mesh_from_memory(text, "stl");
  ASSERT_TRUE(from_memory.ok()) << from_memory.error();
  EXPECT_TRUE(same_geometry(original, *from_memory, 1e-6));
  TemporaryDirectory dir;
  write_file(dir.file("sphere.STL"), text);
  auto from_file = read_mesh(dir.file("sphere.STL"));
  ASSERT_TRUE(from_file.ok()) << from_file.error();
  EXPECT_EQ(from_file->vertex_count(), 42);
  EXPECT_TRUE(validate_balloon_mesh(*from_file).ok());
}

TEST(MeshIo, StlWeldsSignedZerosAndOnlyExactDuplicates) {
  // A tetrahedron whose origin corner is written once as -0: it must still weld. Vertex 3 has a
  // near-duplicate 1e-7 away (a distinct point): it must not weld.
  const std::string stl =
      "solid t\n"
      "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
      "facet normal 0 0 0\nouter loop\nvertex -0 0 -0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
      "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
      "facet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1.0000001\nendloop\nendfacet\n"
      "endsolid t\n";
  auto mesh = read_mesh_from_memory(stl, "stl");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(mesh->vertex_count(), 5);
  const auto report = validate_balloon_mesh(*mesh);
  ASSERT_FALSE(report.ok());
  expect_contains(report.error(), {"open boundary"});
}

TEST(MeshIo, ReadsAsciiPly) {
  const TriMesh original = offset_icosphere(1);
  auto mesh = read_mesh_from_memory(ascii_ply(original), "ply");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_TRUE(same_geometry(original, *mesh, 1e-6));
}

TEST(MeshIo, ReadsGltfAndGlbApplyingNodeTransforms) {
  const TriMesh original = make_icosphere(2.0, 1);
  const std::string moved = R"([{"mesh":0,"translation":[10,20,30]}])";
  const Eigen::RowVector3d shift(10, 20, 30);
  TriMesh expected = original;
  expected.vertices.rowwise() += shift;

  const std::string gltf = gltf_embedded(original, moved, 1);
  const std::string binary = glb(original, moved, 1);
  TemporaryDirectory dir;
  write_file(dir.file("sphere.gltf"), gltf);
  write_file(dir.file("sphere.GLB"), binary);
  const Result<TriMesh> reads[] = {read_mesh_from_memory(gltf, "gltf"), read_mesh_from_memory(binary, "glb"),
                                   read_mesh(dir.file("sphere.gltf")), read_mesh(dir.file("sphere.GLB"))};
  for (const auto& mesh : reads) {
    ASSERT_TRUE(mesh.ok()) << mesh.error();
    EXPECT_TRUE(same_geometry(expected, *mesh, 1e-6));
    TriMesh copy = *mesh;
    const auto report = validate_balloon_mesh(copy);
    ASSERT_TRUE(report.ok()) << report.error();
    EXPECT_FALSE(report->flipped);
  }
}

TEST(MeshIo, GltfWithExternalBufferReadsFromFileOnly) {
  const TriMesh original = make_icosphere(2.0, 1);
  const std::string json = gltf_json(original, R"([{"mesh":0}])", 1, "sphere.bin");
  TemporaryDirectory dir;
  write_file(dir.file("sphere.gltf"), json);
  write_file(dir.file("sphere.bin"), gltf_buffer(original));
  const auto from_file = read_mesh(dir.file("sphere.gltf"));
  ASSERT_TRUE(from_file.ok()) << from_file.error();
  EXPECT_TRUE(same_geometry(original, *from_file, 1e-6));
  // From memory the buffer cannot be found: an error, not a crash.
  const auto from_memory = read_mesh_from_memory(json, "gltf");
  ASSERT_FALSE(from_memory.ok());
  expect_contains(from_memory.error(), {"cannot read gltf mesh data"});
}

TEST(MeshIo, GltfMirroringNodeKeepsTheMeshOutward) {
  // glTF: a negative-determinant transform reverses the winding, so the mirrored mesh stays outward.
  const TriMesh original = make_icosphere(2.0, 1);
  auto mesh = read_mesh_from_memory(gltf_embedded(original, R"([{"mesh":0,"scale":[-1,1,1]}])", 1), "gltf");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  TriMesh mirrored = original;
  mirrored.vertices.col(0) *= -1.0;
  mirrored.faces.col(1).swap(mirrored.faces.col(2));
  EXPECT_TRUE(same_geometry(mirrored, *mesh, 1e-6));
  const auto report = validate_balloon_mesh(*mesh);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_FALSE(report->flipped);
}

TEST(MeshIo, GltfInstancesAreMergedIntoOneMesh) {
  const TriMesh original = make_icosphere(2.0, 1);
  const std::string nodes =
      R"([{"mesh":0},{"mesh":0,"translation":[10,0,0]}])";
  auto mesh = read_mesh_from_memory(gltf_embedded(original, nodes, 2), "gltf");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(mesh->vertex_count(), 84);
  EXPECT_EQ(mesh->face_count(), 160);
  const auto report = validate_balloon_mesh(*mesh);
  ASSERT_FALSE(report.ok());
  expect_contains(report.error(), {"several connected components"});
}

TEST(MeshIo, PolygonFacesAreSplitIntoTrianglesInEveryFormat) {
  // A 20 mm cube of quads, as Blender writes it (each quad counter-clockwise seen from outside). It was
  // refused: "face 0 has 4 vertices; only triangles are supported".
  const std::string cube_obj =
      "v 0 0 0\nv 0 0 20\nv 0 20 0\nv 0 20 20\nv 20 0 0\nv 20 0 20\nv 20 20 0\nv 20 20 20\n"
      "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n";
  std::string cube_off = "OFF\n8 6 0\n0 0 0\n0 0 20\n0 20 0\n0 20 20\n20 0 0\n20 0 20\n20 20 0\n20 20 20\n"
                         "4 0 1 3 2\n4 4 6 7 5\n4 0 4 5 1\n4 2 3 7 6\n4 0 2 6 4\n4 1 5 7 3\n";
  for (const auto& [text, format] : {std::pair{cube_obj, "obj"}, std::pair{cube_off, "off"}}) {
    auto cube = read_mesh_from_memory(text, format);
    ASSERT_TRUE(cube.ok()) << format << ": " << cube.error();
    EXPECT_EQ(cube->vertex_count(), 8);
    EXPECT_EQ(cube->face_count(), 12);
    auto report = validate_balloon_mesh(*cube);
    ASSERT_TRUE(report.ok()) << report.error();
    EXPECT_FALSE(report->flipped) << "the quads' winding is kept";
    EXPECT_NEAR(enclosed_volume(cube->vertices, cube->faces), 8000.0, 1e-9);
  }
  // PLY through assimp: one face of the icosahedron widened to a quad with the next face's first corner.
  auto from_ply = read_mesh_from_memory(ascii_ply(make_icosphere(1.0, 0), 6), "ply");
  ASSERT_TRUE(from_ply.ok()) << from_ply.error();
  EXPECT_EQ(from_ply->face_count(), 21);

  // Not a face, and a face beyond the bound, name the face and the line.
  const std::string two = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 1\nf 1 2 4\nf 1 2\n";
  auto from_obj = read_mesh_from_memory(two, "obj");
  ASSERT_FALSE(from_obj.ok());
  expect_contains(from_obj.error(), {"face 1", "line 6", "has 2 vertices; a face needs at least 3"});
  std::string huge = "OFF\n300 1 0\n";
  for (int i = 0; i < 300; ++i) huge += std::to_string(std::cos(i * 0.02)) + " " + std::to_string(std::sin(i * 0.02)) + " 0\n";
  huge += "300";
  for (int i = 0; i < 300; ++i) {
    huge += ' ';  // appended piecewise: GCC 12's false -Wrestrict on " " + std::string (its bug 105329)
    huge += std::to_string(i);
  }
  auto from_off = read_mesh_from_memory(huge + "\n", "off");
  ASSERT_FALSE(from_off.ok());
  expect_contains(from_off.error(), {"face 0", "has 300 vertices; polygons of up to 256 are split into triangles"});

  TemporaryDirectory dir;
  write_file(dir.file("line.obj"), two);
  auto from_file = read_mesh(dir.file("line.obj"));
  ASSERT_FALSE(from_file.ok());
  expect_contains(from_file.error(), {dir.file("line.obj"), "face 1"});
}

TEST(MeshIo, RejectsUnreadableFilesAndUnknownFormats) {
  TemporaryDirectory dir;
  const std::string missing = dir.file("missing.obj");
  auto result = read_mesh(missing);
  ASSERT_FALSE(result.ok());
  expect_contains(result.error(), {missing, "no such file"});

  write_file(dir.file("mesh.xyz"), "v 0 0 0\n");
  result = read_mesh(dir.file("mesh.xyz"));
  ASSERT_FALSE(result.ok());
  expect_contains(result.error(), {"mesh.xyz", "unsupported format", ".xyz"});

  result = read_mesh(dir.path().string());
  ASSERT_FALSE(result.ok());
  expect_contains(result.error(), {"no file extension"});

  std::filesystem::create_directory(dir.file("folder.stl"));
  result = read_mesh(dir.file("folder.stl"));
  ASSERT_FALSE(result.ok());
  expect_contains(result.error(), {"folder.stl", "directory"});

  write_file(dir.file("empty.off"), "");
  result = read_mesh(dir.file("empty.off"));
  ASSERT_FALSE(result.ok());
  expect_contains(result.error(), {"empty.off", "empty"});

  result = read_mesh_from_memory("v 0 0 0\n", "fbx");
  ASSERT_FALSE(result.ok());
  expect_contains(result.error(), {"unsupported format", "fbx"});
  EXPECT_TRUE(is_readable_mesh_format(".GLB"));
  EXPECT_FALSE(is_readable_mesh_format("fbx"));
  EXPECT_TRUE(is_writable_mesh_format("PLY"));
  EXPECT_FALSE(is_writable_mesh_format("off"));
}

TEST(MeshIo, RejectsParseErrorsAndMeshesWithoutTriangles) {
  struct Case {
    const char* bytes;
    const char* format;
    std::initializer_list<std::string> fragments;
  };
  const Case cases[] = {
      {"v 0 0 0\nv 1 2\n", "obj", {"line 2", "3 coordinates"}},
      {"v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", "obj", {"line 2", "bad vertex coordinate", "'x'"}},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n", "obj", {"face 0", "vertex 5"}},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 0 2\n", "obj", {"bad vertex reference", "face 0"}},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "obj", {"no triangles"}},
      {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "off", {"face 0", "vertex 3", "out of range"}},
      {"OFF\n3 1 0\n0 0 0\n1 0 0\n", "off", {"file ends", "2 of 3 vertices"}},
      {"PLY\n3 1 0\n", "off", {"not an OFF file"}},
      {"4OFF\n3 1 0\n", "off", {"unsupported OFF variant"}},
      {"OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "off", {"no triangles"}},
      {"this is not an stl file at all, and it is certainly not binary either.......................", "stl",
       {"cannot read stl mesh data", "parse error", "the data"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n0 0 0\n",
       "ply",
       {"cannot read ply mesh data"}},
      {"{ not json", "gltf", {"cannot read gltf mesh data", "parse error"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.bytes);
    const auto result = read_mesh_from_memory(c.bytes, c.format);
    ASSERT_FALSE(result.ok());
    expect_contains(result.error(), c.fragments);
    EXPECT_EQ(result.error().find("magic"), std::string::npos) << "assimp's made-up file name leaked";
  }
  EXPECT_FALSE(read_mesh_from_memory("", "obj").ok());
}

TEST(MeshIo, FailedWritesLeaveNoFile) {
  const TriMesh mesh = make_icosphere(1.0, 1);
  TemporaryDirectory dir;

  auto written = write_mesh(mesh, dir.file("sphere.off"));
  ASSERT_FALSE(written.ok());
  expect_contains(written.error(), {"sphere.off", "unsupported format", "obj, stl, ply"});

  written = write_mesh(mesh, dir.file("no/such/folder/sphere.obj"));
  ASSERT_FALSE(written.ok());
  expect_contains(written.error(), {"sphere.obj", "cannot create"});

  // The rename onto an existing folder fails: the temporary file must be gone afterwards.
  std::filesystem::create_directory(dir.file("taken.ply"));
  written = write_mesh(mesh, dir.file("taken.ply"));
  ASSERT_FALSE(written.ok());
  expect_contains(written.error(), {"taken.ply"});
  EXPECT_EQ(dir.entry_count(), 1);
  EXPECT_TRUE(std::filesystem::is_directory(dir.file("taken.ply")));

  TriMesh broken = mesh;
  broken.faces(0, 0) = 1000;
  EXPECT_THROW(write_mesh_to_memory(broken, "obj"), std::invalid_argument);
  EXPECT_THROW(write_mesh_to_memory(mesh, "off"), std::invalid_argument);
}

TEST(MeshIo, OverwritesAnExistingFile) {
  TemporaryDirectory dir;
  const std::string path = dir.file("sphere.obj");
  write_file(path, "old contents that are longer than nothing\n");
  const TriMesh mesh = make_icosphere(1.0, 0);
  ASSERT_TRUE(write_mesh(mesh, path).ok());
  const auto back = read_mesh(path);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back->vertex_count(), 12);
  EXPECT_EQ(dir.entry_count(), 1);
}

// ------------------------------------------------------------------------------------------------
// Hostile uploads (issue 11): the reader reads the uploaded bytes and nothing else, and bounds its work.

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

TEST(MeshIoHostile, GltfNamingAServerFileIsRefusedWithoutReadingIt) {
  // The buffer lies beside us as a valid one: before the fix, assimp read it and returned the mesh.
  const TriMesh original = make_icosphere(2.0, 1);
  TemporaryDirectory dir;
  const std::string buffer_path = dir.file("secret.bin");
  write_file(buffer_path, gltf_buffer(original));
  for (const std::string& uri : {buffer_path, std::string("file://") + buffer_path, std::string("/dev/zero"),
                                 std::string("secret.bin"), std::string("../../etc/passwd")}) {
    SCOPED_TRACE(uri);
    const auto result = read_mesh_from_memory(gltf_json(original, R"([{"mesh":0}])", 1, uri), "gltf");
    ASSERT_FALSE(result.ok());
    expect_contains(result.error(), {"cannot read gltf mesh data", "external", uri.substr(0, 40), "data: URIs"});
  }
}

TEST(MeshIoHostile, GltfWhoseUriKeyEvadesTheScanIsStillSealed) {
  // "\u0075ri" is "uri" to a JSON parser but not to the quick scan: the sealed I/O system refuses it.
  const TriMesh original = make_icosphere(2.0, 1);
  TemporaryDirectory dir;
  const std::string buffer_path = dir.file("secret.bin");
  write_file(buffer_path, gltf_buffer(original));
  std::string json = gltf_json(original, R"([{"mesh":0}])", 1, buffer_path);
  const std::size_t key = json.find("\"uri\"");
  ASSERT_NE(key, std::string::npos);
  json.replace(key, 5, "\"\\u0075ri\"");
  const auto result = read_mesh_from_memory(json, "gltf");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().find("parse error: "), std::string::npos) << result.error();
  expect_contains(result.error(), {"outside the upload", buffer_path});
}

TEST(MeshIoHostile, GlbWithAnExternalBufferIsRefused) {
  const TriMesh original = make_icosphere(2.0, 1);
  std::string binary = glb(original, R"([{"mesh":0}])", 1);
  // Turn the GLB's own buffer into an external one of the same length: {"byteLength":N} gains a uri.
  const std::string json = gltf_json(original, R"([{"mesh":0}])", 1, "/etc/hostname");
  std::string padded = json;
  padded.resize((json.size() + 3) / 4 * 4, ' ');
  std::string external = binary.substr(0, 12);
  const auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  external += u32(static_cast<std::uint32_t>(padded.size())) + "JSON" + padded;
  const auto result = read_mesh_from_memory(external, "glb");
  ASSERT_FALSE(result.ok());
  expect_contains(result.error(), {"cannot read glb mesh data", "/etc/hostname"});
  EXPECT_TRUE(read_mesh_from_memory(binary, "glb").ok());
}

std::string binary_stl_of_nan_triangles(std::uint32_t triangles) {
  std::string out(80, ' ');
  out.append(reinterpret_cast<const char*>(&triangles), 4);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::string record;
  for (int k = 0; k < 12; ++k) record.append(reinterpret_cast<const char*>(&nan), 4);
  record.append(2, '\0');
  for (std::uint32_t t = 0; t < triangles; ++t) out += record;
  return out;
}

TEST(MeshIoHostile, NonFiniteCoordinatesAreRefusedBeforeWelding) {
  // 80k NaN triangles welded in 81 s before (NaN keys never compare equal): now refused at the first vertex.
  const auto stl = read_mesh_from_memory(binary_stl_of_nan_triangles(80000), "stl");
  ASSERT_FALSE(stl.ok());
  expect_contains(stl.error(), {"non-finite", "vertex 0"});
  for (const char* obj : {"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                          "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"}) {
    SCOPED_TRACE(obj);
    const auto result = read_mesh_from_memory(obj, "obj");
    ASSERT_FALSE(result.ok());
    expect_contains(result.error(), {"line 1", "bad vertex coordinate"});
  }
  const auto off = read_mesh_from_memory("OFF\n3 1 0\nnan 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "off");
  ASSERT_FALSE(off.ok());
  expect_contains(off.error(), {"bad coordinate", "vertex 0"});
}

TEST(MeshIoHostile, HeaderBombsAreRefusedBeforeAllocation) {
  const auto off = read_mesh_from_memory("OFF\n700000000 700000000 0\n0 0 0\n", "off");
  ASSERT_FALSE(off.ok());
  expect_contains(off.error(), {"header declares 700000000 vertices", "bytes can hold"});
  const auto ply = read_mesh_from_memory(
      "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
      "ply");
  ASSERT_FALSE(ply.ok());
  expect_contains(ply.error(), {"bad PLY header", "4000000000 vertex elements"});
  // A binary STL whose size matches 2M triangles, over a 1M-face limit: refused from the header.
  std::string stl(84, ' ');
  const std::uint32_t count = 3;
  std::memcpy(stl.data() + 80, &count, 4);
  stl.append(150, '\0');
  const auto limited = read_mesh_from_memory(stl, "stl", MeshReadLimits{0, 2});
  ASSERT_FALSE(limited.ok());
  expect_contains(limited.error(), {"too many faces: 3 (the limit is 2)"});
  EXPECT_TRUE(is_over_limit_error(limited.error()));
}

TEST(MeshIoHostile, InputsThatAssimpMishandlesAreRefusedBeforeIt) {
  // Found by tests/fuzz: assimp 5.2 loops for ever on this PLY header (an element without a name)...
  const auto nameless = read_mesh_from_memory("ply\nformat ascii 1.0\nelement 1\n1 0.125 0.625\nend_header\n", "ply");
  ASSERT_FALSE(nameless.ok());
  expect_contains(nameless.error(), {"bad PLY header: line 3", "element NAME COUNT"});
  // ...and leaks its arrays when an ASCII PLY or STL number, or a glTF's base64, does not parse.
  const std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const auto ply = read_mesh_from_memory(ply_header + "0 0 0\n1 0 0\n0 1 x0\n3 0 1 2\n", "ply");
  ASSERT_FALSE(ply.ok());
  expect_contains(ply.error(), {"bad PLY data: line 12", "'x0' is not a float"});
  ASSERT_TRUE(read_mesh_from_memory(ply_header + "0 0 0\n1 0 0\n0 1 -1e-3\n3 0 1 2\n", "ply").ok());
  // Found by the 10-minute fuzz_mesh_ply run (tests/fuzz/regressions/ply-leak-8be8d00b.ply): two signs.
  const auto two_signs = read_mesh_from_memory(ply_header + "0 0 0\n1 0 0\n0 +-1 1\n3 0 1 2\n", "ply");
  ASSERT_FALSE(two_signs.ok());
  expect_contains(two_signs.error(), {"bad PLY data: line 12", "'+-1' is not a float"});
  const auto found = read_mesh_from_memory(read_bytes(std::string(BALLOON_FUZZ_REGRESSIONS_DIR) + "/ply-leak-8be8d00b.ply"), "ply");
  ASSERT_FALSE(found.ok());
  expect_contains(found.error(), {"bad PLY data: line 519", "'+-1' is not a float"});
  ASSERT_TRUE(read_mesh_from_memory(ply_header + "0 0 0\n1 0 0\n0 +1 1\n3 0 1 2\n", "ply").ok());
  // Found by fuzz_mesh_ply in session 43's CI (valgrind named the input; ASan saw only a corrupt heap later):
  // 'element vertex 12' with x only, then 'element vertex 13' with x y z. assimp 5.2 sized its vertex
  // array from one and wrote the other's past its end.
  const auto twice = read_mesh_from_memory(read_bytes(std::string(BALLOON_FUZZ_REGRESSIONS_DIR) + "/ply-overflow-70659735.ply"), "ply");
  ASSERT_FALSE(twice.ok());
  expect_contains(twice.error(), {"bad PLY header: line 7", "element 'vertex' is declared twice"});
  // A header of 100,000 comment lines kept assimp busy for 17 s (its header parser is quadratic).
  std::string long_header = "ply\nformat ascii 1.0\n";
  for (int line = 0; line < 100000; ++line) long_header += "comment x\n";
  const auto slow = read_mesh_from_memory(long_header + "element vertex 0\nproperty float x\nend_header\n", "ply");
  ASSERT_FALSE(slow.ok());
  expect_contains(slow.error(), {"bad PLY header: more than 1000 lines before end_header"});
  // Lines out of step with the header: assimp read a coordinate as a face's list length, and leaked.
  const auto short_line = read_mesh_from_memory(ply_header + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "ply");
  ASSERT_FALSE(short_line.ok());
  expect_contains(short_line.error(), {"bad PLY data: line 11", "fewer values than the header's properties"});
  const auto float_index = read_mesh_from_memory(ply_header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n", "ply");
  ASSERT_FALSE(float_index.ok());
  expect_contains(float_index.error(), {"bad PLY data: line 13", "'2.5' is not a int"});
  const auto stl = read_mesh_from_memory(
      "solid s\nfacet normal 0 0 0\nouter loop\nvertex 8.5dae 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
      "endsolid s\n", "stl");
  ASSERT_FALSE(stl.ok());
  expect_contains(stl.error(), {"bad ASCII STL: line 4", "'8.5dae' is not a number"});
  const auto empty_facet = read_mesh_from_memory("solid s\nfacet normal 0 0 0\nouter loop\nendfacet\nendsolid s\n", "stl");
  ASSERT_FALSE(empty_facet.ok());
  expect_contains(empty_facet.error(), {"bad ASCII STL: line 4", "expected 'vertex', found 'endfacet'"});
  const auto inner_cr = read_mesh_from_memory(
      "solid s\r\nfacet normal 0 0 0\r\nouter loop\r\nvertex 0 0 0\r\nvertex 1 0\r0\r\nvertex 0 1 0\r\nendloop\r\n"
      "endfacet\r\nendsolid s\r\n", "stl");
  ASSERT_FALSE(inner_cr.ok());
  expect_contains(inner_cr.error(), {"bad ASCII STL: line 5", "expected 3 numbers after 'vertex'"});
  const auto gltf = read_mesh_from_memory(
      R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":3,"uri":"data:application/octet-stream;base64,AA\u00e9A"}]})",
      "gltf");
  ASSERT_FALSE(gltf.ok());
  expect_contains(gltf.error(), {"bad base64 in a data: URI"});
  // Found by the catalogue: rapidjson recursed once per level, and 200,000 levels overflowed the stack.
  const auto deep = read_mesh_from_memory(
      R"({"asset":{"version":"2.0"},"extras":)" + std::string(200000, '[') + std::string(200000, ']') + "}", "gltf");
  ASSERT_FALSE(deep.ok());
  expect_contains(deep.error(), {"nested deeper than 64 levels"});
  // A node tree 20,000 deep in a flat array overflowed it too (each node the child of the one before).
  std::string chain = R"({"asset":{"version":"2.0"},"nodes":[)";
  for (int i = 0; i < 20000; ++i) chain += R"({"children":[)" + std::to_string(i + 1) + "]},";
  chain += "{}]}";
  const auto deep_nodes = read_mesh_from_memory(chain, "gltf");
  ASSERT_FALSE(deep_nodes.ok());
  expect_contains(deep_nodes.error(), {"more than 4096 objects"});
}

/// `json` with the first `from` replaced by `to` (which must be there: a fixture that changed fails here).
std::string replaced(std::string json, const std::string& from, const std::string& to) {
  const std::size_t at = json.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? json : json.replace(at, from.size(), to);
}

TEST(MeshIoHostile, GltfLayoutsThatAssimpTrustsAreChecked) {
  // Found by tests/fuzz (seed 1, 2,209 runs): a byteStride taking the index accessor past its buffer view.
  // assimp 5.2 checks an accessor's length without the stride, allocated the faces, then threw on the first
  // index past the view and leaked them (27,656 bytes here, as large as the index count makes them).
  const std::string found = read_bytes(std::string(BALLOON_FUZZ_REGRESSIONS_DIR) + "/glb-leak-60f7694b.glb");
  ASSERT_EQ(found.size(), 31644u);
  const auto refused = read_mesh_from_memory(found, "glb");
  ASSERT_FALSE(refused.ok());
  expect_contains(refused.error(), {"cannot read glb mesh data: bad glTF: buffer view 1: byteStride 10392"});

  const TriMesh sphere = make_icosphere(2.0, 1);  // 42 vertices, 80 faces: 504 bytes of positions, 960 of indices
  const std::string gltf = gltf_embedded(sphere, R"([{"mesh":0}])", 1);
  ASSERT_TRUE(read_mesh_from_memory(gltf, "gltf").ok());
  const auto check = [](const std::string& bytes, const char* format, std::initializer_list<std::string> fragments) {
    const auto result = read_mesh_from_memory(bytes, format);
    ASSERT_FALSE(result.ok());
    expect_contains(result.error(), fragments);
  };
  // The same class within the stride range the specification allows.
  check(replaced(gltf, R"("byteLength":960,)", R"("byteLength":960,"byteStride":8,)"), "gltf",
        {"bad glTF: accessor 1 (240 elements of 4 bytes, 8 apart, from offset 0) does not fit in buffer view 1 (960 bytes)"});
  check(replaced(gltf, R"("componentType":5125,"count":240)", R"("byteOffset":4,"componentType":5125,"count":240)"),
        "gltf", {"accessor 1 (240 elements of 4 bytes, 4 apart, from offset 4) does not fit"});
  check(replaced(gltf, R"("byteOffset":504,"byteLength":960)", R"("byteOffset":600,"byteLength":960)"), "gltf",
        {"bad glTF: buffer view 1 (offset 600, length 960) ends past buffer 0 (1464 bytes)"});
  // A strip of fewer than 3 indices; sparse indices without a view (assimp 5.2 dereferences the missing view:
  // SEGV); a POSITION that is not VEC3 float (assimp reads it as if it were).
  check(replaced(replaced(gltf, R"("mode":4)", R"("mode":5)"), R"("componentType":5125,"count":240)",
                 R"("componentType":5125,"count":2)"),
        "gltf", {"mesh 0 primitive 0 has 2 indices, fewer than one primitive of mode 5 needs"});
  check(replaced(gltf, R"("type":"SCALAR")", R"("type":"SCALAR","sparse":{"count":1,"indices":{"componentType":5125},"values":{"bufferView":0}})"),
        "gltf", {"accessor 1 sparse indices has no 'bufferView'"});
  // An indexed line loop with an index past the vertices: assimp 5.2 dereferenced the skipped face (SEGV;
  // tests/fuzz/regressions/glb-segv-24ad948d.glb, found by fuzz_mesh_glb).
  const std::string segv = read_bytes(std::string(BALLOON_FUZZ_REGRESSIONS_DIR) + "/glb-segv-24ad948d.glb");
  ASSERT_EQ(segv.size(), 1479u);
  check(segv, "glb", {"bad glTF: mesh 0 primitive 0: indexed LINE_LOOP primitives (mode 2) are not supported"});
  check(replaced(gltf, R"("mode":4)", R"("mode":6)"), "gltf", {"indexed TRIANGLE_FAN primitives (mode 6) are not supported"});
  check(replaced(gltf, R"("count":42,"type":"VEC3")", R"("count":42,"type":"VEC2")"), "gltf",
        {"mesh 0 primitive 0 POSITION (accessor 0) must be VEC3 of componentType 5126, not VEC2 of 5126"});
  check(replaced(gltf, R"("scene":0,)", R"("scene":0,"scene":1,)"), "gltf", {"the key 'scene' is repeated in one object"});
  check(replaced(gltf, R"("scene":0,)", R"("scene":0,"skins":[{"joints":[0]}],)"), "gltf", {"skins are not supported"});
  check(replaced(gltf, R"("mode":4)", R"("mode":4,"extensions":{"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{"POSITION":0}}})"),
        "gltf", {"bad glTF: Draco-compressed meshes (KHR_draco_mesh_compression) are not supported"});
  // A data: URI with bad base64 leaked its decoded buffer in assimp; the raw scan misses an escaped "uri" key.
  check(replaced(gltf, R"("uri":"data:application/octet-stream;base64,)", R"("\u0075ri":"data:application/octet-stream;base64,*)"),
        "gltf", {"bad glTF: buffer 0: a data: URI that is not strict base64"});
  // A GLB's binary chunk shorter than the buffer the JSON declares on it.
  const std::string binary = glb(sphere, R"([{"mesh":0}])", 1);
  ASSERT_TRUE(read_mesh_from_memory(binary, "glb").ok());
  std::string short_bin = binary.substr(0, binary.size() - 8);
  const std::uint32_t json_length = static_cast<std::uint32_t>(static_cast<unsigned char>(binary[12])) |
                                    static_cast<std::uint32_t>(static_cast<unsigned char>(binary[13])) << 8;
  const std::uint32_t bin_length = 1464 - 8;
  std::memcpy(short_bin.data() + 20 + json_length, &bin_length, 4);
  check(short_bin, "glb", {"bad glTF: buffer 0 declares 1464 bytes but the GLB's binary chunk has 1456"});
}

TEST(MeshIoHostile, GltfWithStridedInterleavedDataIsRead) {
  // The layout check must not refuse what the specification allows: positions 16 bytes apart (each followed
  // by 4 bytes of padding), the view ending right after the last one's padding.
  const TriMesh sphere = make_icosphere(2.0, 1);
  std::string buffer;
  const std::string packed = gltf_buffer(sphere);
  for (int v = 0; v < sphere.vertex_count(); ++v) buffer += packed.substr(static_cast<std::size_t>(v) * 12, 12) + std::string(4, '\0');
  buffer += packed.substr(504);
  std::string gltf = gltf_embedded(sphere, R"([{"mesh":0}])", 1);
  gltf = replaced(gltf, R"("byteLength":1464)", R"("byteLength":1632)");
  gltf = replaced(gltf, R"("byteOffset":0,"byteLength":504)", R"("byteOffset":0,"byteLength":672,"byteStride":16)");
  gltf = replaced(gltf, R"("byteOffset":504,"byteLength":960)", R"("byteOffset":672,"byteLength":960)");
  gltf = replaced(gltf, base64(packed), base64(buffer));
  const auto strided = read_mesh_from_memory(gltf, "gltf");
  ASSERT_TRUE(strided.ok()) << strided.error();
  EXPECT_TRUE(same_geometry(sphere, *strided, 1e-6));
}

TEST(MeshIoHostile, BinaryPlyListsAreCheckedBeforeAssimp) {
  // Found by tests/fuzz (fuzz_mesh_ply, 10-minute run, execution 24,921): a float list length. assimp 5.2
  // read it as a huge count, ran past the end and leaked the mesh it had built (29,973 bytes).
  const std::string found = read_bytes(std::string(BALLOON_FUZZ_REGRESSIONS_DIR) + "/ply-leak-200100cb.ply");
  ASSERT_EQ(found.size(), 27271u);
  const auto refused = read_mesh_from_memory(found, "ply");
  ASSERT_FALSE(refused.ok());
  expect_contains(refused.error(), {"bad PLY header: line 9: a list's length type must be an integer type, not 'float'"});

  const TriMesh sphere = make_icosphere(1.0, 1);  // 42 vertices of 3 doubles, 80 faces of 1 + 3 x 4 bytes
  const std::string binary = write_mesh_to_memory(sphere, "ply");
  ASSERT_TRUE(read_mesh_from_memory(binary, "ply").ok());
  const std::size_t body = binary.find("end_header\n") + 11;
  ASSERT_EQ(binary.size() - body, 42u * 24 + 80u * 13);
  // A signed length of -1: assimp 5.2 sized the list from it as unsigned (32 GB for a 30 kB file).
  std::string negative = replaced(binary, "property list uchar int", "property list char  int");
  negative[body + 42 * 24 + 13 * 5] = '\xff';
  const auto negative_result = read_mesh_from_memory(negative, "ply");
  ASSERT_FALSE(negative_result.ok());
  expect_contains(negative_result.error(), {"bad PLY data: face 5: a negative list length"});
  // A list running past the end, and a body cut short.
  std::string long_list = binary;
  long_list[body + 42 * 24 + 13 * 79] = '\x04';
  const auto long_result = read_mesh_from_memory(long_list, "ply");
  ASSERT_FALSE(long_result.ok());
  expect_contains(long_result.error(), {"bad PLY data: face 79: the data ends before the header's elements do"});
  const auto cut = read_mesh_from_memory(binary.substr(0, binary.size() - 5), "ply");
  ASSERT_FALSE(cut.ok());
  expect_contains(cut.error(), {"bad PLY data: face 79: the data ends"});
  // An element without properties would make assimp loop over its count reading nothing.
  const auto empty = read_mesh_from_memory(replaced(binary, "element face", "element junk 1000000000\nelement face"), "ply");
  ASSERT_FALSE(empty.ok());
  expect_contains(empty.error(), {"element 'junk' has no properties"});
}

TEST(MeshIoHostile, OnlyTheDeclaredFormatsImporterReadsTheBytes) {
  // assimp's ReadFile guesses another format when the declared one's importer declines: an OBJ sent as
  // STL or glTF was read by the OBJ importer. Now the declared importer alone reads it, and refuses it.
  const std::string obj = write_mesh_to_memory(make_icosphere(1.0, 0), "obj");
  for (const char* format : {"stl", "gltf", "glb"}) {
    SCOPED_TRACE(format);
    const auto result = read_mesh_from_memory(obj, format);
    EXPECT_FALSE(result.ok());
  }
}

TEST(MeshIoHostile, LimitsHoldForEveryFormat) {
  const TriMesh sphere = make_icosphere(1.0, 2);  // 162 vertices, 320 faces
  const MeshReadLimits few_vertices{100, 0};
  const MeshReadLimits few_faces{0, 100};
  for (const char* format : {"obj", "stl", "ply"}) {
    SCOPED_TRACE(format);
    const std::string bytes = write_mesh_to_memory(sphere, format);
    ASSERT_TRUE(read_mesh_from_memory(bytes, format, MeshReadLimits{162, 320}).ok());
    const auto vertices = read_mesh_from_memory(bytes, format, few_vertices);
    ASSERT_FALSE(vertices.ok());
    EXPECT_TRUE(is_over_limit_error(vertices.error())) << vertices.error();
    expect_contains(vertices.error(), {"too many vertices", "limit is 100"});
    const auto faces = read_mesh_from_memory(bytes, format, few_faces);
    ASSERT_FALSE(faces.ok());
    expect_contains(faces.error(), {"too many faces", "limit is 100"});
  }
  // glTF instancing repeats one mesh: the limit holds for the merged mesh, not for the file.
  const auto instanced = read_mesh_from_memory(
      gltf_embedded(sphere, R"([{"mesh":0},{"mesh":0,"translation":[5,0,0]}])", 2), "gltf", MeshReadLimits{200, 0});
  ASSERT_FALSE(instanced.ok());
  expect_contains(instanced.error(), {"too many vertices: 324 (the limit is 200)"});
  EXPECT_FALSE(is_over_limit_error("face 12 has too many neighbours"));
}

TEST(MeshIo, AnObjFarFromTheOriginKeepsItsVerticesToAHundredMillionthOfItsSize) {
  const TriMesh sphere = make_icosphere(20.0, 1);
  for (double offset : {0.0, 1e5, 1e9}) {
    TriMesh far = sphere;
    far.vertices.rowwise() += Eigen::RowVector3d(offset, 2.0 * offset, -offset);
    const Result<TriMesh> back = read_mesh_from_memory(write_mesh_to_memory(far, "obj"), "obj");
    ASSERT_TRUE(back) << back.error();
    // 9 significant digits had written every x of the sphere at 1e12 mm as 1e+12.
    EXPECT_LT((back->vertices - far.vertices).cwiseAbs().maxCoeff(), 1e-8 * 40.0) << offset;
  }
}

}  // namespace
}  // namespace balloon

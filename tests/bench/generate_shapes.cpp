// Writes the shapes of tests/shapes/implicit_shapes.hpp (flat faces, dents, thin tubes, handles, limbs:
// shapes nobody tuned the solvers for) as OUT_DIR/meshes/<family>_<seed>.obj with
// OUT_DIR/meshes/PROVENANCE.md, a DATA_DIR for bench_robustness (`bench_robustness OUT_DIR`).
// Usage: generate_shapes OUT_DIR [--seed N=1] [--size S=0.03 (the mesher's triangle size, units of the
//        shapes' ~2-unit extent)]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "implicit_shapes.hpp"
#include "mesh/mesh_io.hpp"

int main(int argc, char** argv) {
  const auto usage = [] {
    std::fprintf(stderr, "usage: generate_shapes OUT_DIR [--seed N] [--size S]\n");
    return 2;
  };
  std::string out_dir;
  unsigned seed = 1;
  double size = 0.03;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--seed" && i + 1 < argc) {
      seed = static_cast<unsigned>(std::strtoul(argv[++i], nullptr, 10));
    } else if (arg == "--size" && i + 1 < argc) {
      size = std::atof(argv[++i]);
    } else if (!arg.empty() && arg[0] != '-' && out_dir.empty()) {
      out_dir = arg;
    } else {
      return usage();
    }
  }
  if (out_dir.empty() || !(size > 0.0)) {
    return usage();
  }
  const std::filesystem::path meshes = std::filesystem::path(out_dir) / "meshes";
  std::error_code error;
  std::filesystem::create_directories(meshes, error);
  if (error) {
    std::fprintf(stderr, "generate_shapes: cannot create %s: %s\n", meshes.string().c_str(), error.message().c_str());
    return 1;
  }
  std::ofstream provenance(meshes / "PROVENANCE.md");
  provenance << "# Generated shapes\n\n`generate_shapes " << out_dir << " --seed " << seed << " --size " << size
             << "`: implicit surfaces meshed by CGAL's surface mesher (angle 25 degrees, size " << size
             << ", distance " << 0.1 * size << "), closed and manifold by construction.\n\n";
  for (const auto& shape : balloon::test_shapes::implicit_shapes(seed, size)) {
    const std::string file = (meshes / (shape.name + ".obj")).string();
    if (auto written = balloon::write_mesh(shape.mesh, file); !written) {
      std::fprintf(stderr, "generate_shapes: %s\n", written.error().c_str());
      return 1;
    }
    provenance << "- `" << shape.name << ".obj`: " << shape.features << "; " << shape.mesh.vertex_count()
               << " vertices\n";
    std::printf("%-24s %7d vertices %7d triangles  %s\n", shape.name.c_str(), shape.mesh.vertex_count(),
                shape.mesh.face_count(), shape.features.c_str());
  }
  return 0;
}

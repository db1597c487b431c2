#pragma once
/// Shapes nobody tuned the solvers for (issue 10: "build for shapes in general"): closed surfaces meshed
/// from implicit functions with CGAL's surface mesher, with the features the corpus has and more of them:
/// flat faces with rounded or sharp rims, dents (concave regions), thin tubes and limbs, handles (genus 1
/// and 2) and thin necks. The same seed gives the same shapes; another seed moves every size, position
/// and exponent within its family. Used by the bench tool generate_shapes and by the tests.
#include <string>
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon::test_shapes {

struct ImplicitShape {
  std::string name;      ///< family_seed
  std::string features;  ///< what the family exercises, in words
  TriMesh mesh;          ///< closed, manifold, outward; about 2 units across (unitless: scale it to mm)
};

/// Every family with its parameters drawn from `seed`, meshed with triangles of about `size` (units of
/// the ~2-unit extent; 0.03 gives 2-7k vertices). A family the mesher finds no surface for is left out.
std::vector<ImplicitShape> implicit_shapes(unsigned seed, double size);

}  // namespace balloon::test_shapes

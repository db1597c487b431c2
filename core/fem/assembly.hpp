#pragma once
/// The one path from per-triangle 9x9 blocks into a global sparse matrix. The sparsity pattern of the
/// free coordinates is built once per mesh, with a precomputed slot for every element entry, so
/// assembly is a plain scatter with no search.
#include <Eigen/Core>
#include <vector>

#include "fem/hinge_bending.hpp"
#include "fem/membrane_element.hpp"
#include "mesh/tri_mesh.hpp"

namespace balloon::fem {

/// Upper triangle (row <= column) of a symmetric matrix over the free coordinates, in compressed-column
/// form, plus the slots of every triangle's 9x9 block (and every bending hinge's 12x12 block).
class TriangleAssembly {
 public:
  /// `fixed_coordinate` has 3#V entries (x0, y0, z0, x1, ...); fixed coordinates get no row or column.
  /// `hinges` (bending on) widens the pattern to the vertices across each edge.
  TriangleAssembly(const Faces& faces, int vertex_count, const std::vector<bool>& fixed_coordinate,
                   const std::vector<HingeVertices>& hinges = {});
  /// A pattern wider than one triangle: every two vertices of one group couple (e.g. each vertex with
  /// its one-ring, for a Gauss-Newton J^T J whose rows are per vertex). Filled with add_block and
  /// add_entry; add() needs the triangle constructor.
  TriangleAssembly(const std::vector<std::vector<int>>& vertex_groups, int vertex_count,
                   const std::vector<bool>& fixed_coordinate);

  int free_count() const { return m_free_count; }
  /// Free index of a coordinate, or -1 when it is fixed.
  int free_index(int coordinate) const { return m_free_index[static_cast<size_t>(coordinate)]; }
  const std::vector<int>& column_starts() const { return m_column_starts; }
  const std::vector<int>& row_indices() const { return m_row_indices; }
  std::vector<double>& values() { return m_values; }
  const std::vector<double>& values() const { return m_values; }

  void set_zero();
  /// Adds a symmetric 9x9 block of triangle `face` (its corners in face order).
  void add(int face, const Matrix9d& block);
  /// Adds a symmetric 12x12 block of hinge `hinge` (index into the constructor's hinges).
  void add_hinge(int hinge, const Matrix12d& block);
  /// Adds a symmetric block over `coordinates` (block(i, j) at coordinates i, j): its upper triangle in
  /// the free numbering, fixed coordinates skipped. Every pair must be in the pattern (else
  /// std::out_of_range). Looks each entry up: for blocks other than the triangles' own.
  void add_block(const std::vector<int>& coordinates, const Eigen::MatrixXd& block);
  /// Adds `value` at (row, column) when both coordinates are free and the row's free index is not
  /// above the column's: a symmetric matrix given entry by entry lists its lower triangle as a mirror of
  /// the upper, which is the part stored. std::out_of_range when the pair is not in the pattern.
  void add_entry(int row_coordinate, int column_coordinate, double value);
  /// Adds `value` to the diagonal of every free coordinate.
  void add_to_diagonal(double value);
  /// Mean absolute diagonal entry (scale for shifts).
  double mean_abs_diagonal() const;

  /// Full 3#V vector -> free coordinates.
  Eigen::VectorXd restrict(const Eigen::VectorXd& full) const;
  /// Free coordinates -> full 3#V vector with zeros at fixed coordinates.
  Eigen::VectorXd extend(const Eigen::VectorXd& free) const;
  /// y = A x for the assembled symmetric matrix (free coordinates).
  Eigen::VectorXd multiply(const Eigen::VectorXd& x) const;

 private:
  /// Numbers the free coordinates (m_free_index, m_free_to_coordinate).
  void number_free_coordinates(const std::vector<bool>& fixed_coordinate);
  /// Compressed columns (upper part, every diagonal kept), zero values and the diagonal slots, from the
  /// vertices each vertex couples with (any order, repeats allowed; sorted in place).
  void set_pattern(std::vector<std::vector<int>>& coupled);
  /// Slot of (row, column) in free numbering, row <= column; -1 when not in the pattern.
  int slot(int row, int column) const;

  int m_free_count = 0;
  std::vector<int> m_free_index;
  std::vector<int> m_free_to_coordinate;
  std::vector<int> m_column_starts;
  std::vector<int> m_row_indices;
  std::vector<double> m_values;
  std::vector<int> m_diagonal_slots;
  std::vector<int> m_element_slots;  // 81 per face, -1 for skipped entries
  std::vector<int> m_hinge_slots;    // 144 per hinge, likewise
};

}  // namespace balloon::fem

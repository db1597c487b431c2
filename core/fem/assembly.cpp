#include "fem/assembly.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace balloon::fem {

TriangleAssembly::TriangleAssembly(const Faces& faces, int vertex_count, const std::vector<bool>& fixed_coordinate,
                                   const std::vector<HingeVertices>& hinges) {
  if (static_cast<int>(fixed_coordinate.size()) != 3 * vertex_count)
    throw std::invalid_argument("TriangleAssembly: fixed_coordinate must have 3#V entries");
  number_free_coordinates(fixed_coordinate);
  for (const auto& hinge : hinges)
    for (int v : hinge)
      if (v < 0 || v >= vertex_count) throw std::invalid_argument("TriangleAssembly: a hinge vertex does not exist");

  // Vertices coupled by a triangle or a hinge.
  std::vector<std::vector<int>> coupled(static_cast<size_t>(vertex_count));
  auto couple = [&](const int* vertices, int corners) {
    for (int i = 0; i < corners; ++i)
      for (int j = 0; j < corners; ++j)
        if (i != j) coupled[static_cast<size_t>(vertices[i])].push_back(vertices[j]);
  };
  for (int f = 0; f < faces.rows(); ++f) couple(&faces(f, 0), 3);
  for (const auto& hinge : hinges) couple(hinge.data(), 4);
  set_pattern(coupled);

  // Slot of every stencil entry (l, k), column-major as the element blocks store it; -1 when skipped. A
  // vertex's free rows sit next to each other in a column, so one search per vertex and column finds them.
  auto stencil_slots = [&](const int* vertices, int corners, int* slots) {
    const int n = 3 * corners;
    for (int j = 0; j < corners; ++j) {
      for (int b = 0; b < 3; ++b) {
        const int k = 3 * j + b;
        const int col = m_free_index[static_cast<size_t>(3 * vertices[j] + b)];
        for (int i = 0; i < corners; ++i) {
          int* entry = slots + 3 * i + n * k;
          int next = -1;
          for (int a = 0; a < 3; ++a) {
            const int row = m_free_index[static_cast<size_t>(3 * vertices[i] + a)];
            if (col < 0 || row < 0 || row > col) {
              entry[a] = -1;
              continue;
            }
            next = next < 0 ? slot(row, col) : next + 1;
            entry[a] = next;
          }
        }
      }
    }
  };
  m_element_slots.resize(static_cast<size_t>(faces.rows()) * 81);
  for (int f = 0; f < faces.rows(); ++f) stencil_slots(&faces(f, 0), 3, &m_element_slots[static_cast<size_t>(f) * 81]);
  m_hinge_slots.resize(hinges.size() * 144);
  for (size_t h = 0; h < hinges.size(); ++h) stencil_slots(hinges[h].data(), 4, &m_hinge_slots[h * 144]);
}

TriangleAssembly::TriangleAssembly(const std::vector<std::vector<int>>& vertex_groups, int vertex_count,
                                   const std::vector<bool>& fixed_coordinate) {
  if (static_cast<int>(fixed_coordinate.size()) != 3 * vertex_count)
    throw std::invalid_argument("TriangleAssembly: fixed_coordinate must have 3#V entries");
  number_free_coordinates(fixed_coordinate);
  std::vector<std::vector<int>> coupled(static_cast<size_t>(vertex_count));
  for (const auto& group : vertex_groups) {
    for (int v : group)
      if (v < 0 || v >= vertex_count) throw std::invalid_argument("TriangleAssembly: a group vertex does not exist");
    for (int v : group) coupled[static_cast<size_t>(v)].insert(coupled[static_cast<size_t>(v)].end(), group.begin(), group.end());
  }
  set_pattern(coupled);
}

void TriangleAssembly::number_free_coordinates(const std::vector<bool>& fixed_coordinate) {
  const int coordinates = static_cast<int>(fixed_coordinate.size());
  m_free_index.assign(static_cast<size_t>(coordinates), -1);
  for (int c = 0; c < coordinates; ++c) {
    if (!fixed_coordinate[static_cast<size_t>(c)]) {
      m_free_index[static_cast<size_t>(c)] = m_free_count++;
      m_free_to_coordinate.push_back(c);
    }
  }
}

void TriangleAssembly::set_pattern(std::vector<std::vector<int>>& coupled) {
  // Built per vertex and expanded to its free coordinates: free indices follow vertex order, so each
  // column's rows come out sorted, with no per-coordinate lists to sort (at 100k vertices those took 0.32 s
  // of every inflation's set-up). Counted, then filled, so the rows take exactly their size.
  for (size_t v = 0; v < coupled.size(); ++v) {
    auto& vertices = coupled[v];
    vertices.push_back(static_cast<int>(v));  // always keep the diagonal, even for an isolated vertex
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  }
  auto for_each_column = [&](auto&& visit) {  // (vertex, free column), in column order
    for (int v = 0; v < static_cast<int>(coupled.size()); ++v)
      for (int b = 0; b < 3; ++b)
        if (const int col = m_free_index[static_cast<size_t>(3 * v + b)]; col >= 0) visit(v, col);
  };
  auto for_each_row = [&](int v, int col, auto&& visit) {
    for (int u : coupled[static_cast<size_t>(v)]) {
      if (u > v) break;  // every row of a later vertex is below the diagonal
      for (int a = 0; a < 3; ++a)
        if (const int row = m_free_index[static_cast<size_t>(3 * u + a)]; row >= 0 && row <= col) visit(row);
    }
  };
  m_column_starts.assign(static_cast<size_t>(m_free_count) + 1, 0);
  for_each_column([&](int v, int col) {
    int count = 0;
    for_each_row(v, col, [&](int) { ++count; });
    m_column_starts[static_cast<size_t>(col) + 1] = m_column_starts[static_cast<size_t>(col)] + count;
  });
  m_row_indices.resize(static_cast<size_t>(m_column_starts.back()));
  for_each_column([&](int v, int col) {
    int next = m_column_starts[static_cast<size_t>(col)];
    for_each_row(v, col, [&](int row) { m_row_indices[static_cast<size_t>(next++)] = row; });
  });
  m_values.assign(m_row_indices.size(), 0.0);
  m_diagonal_slots.resize(static_cast<size_t>(m_free_count));
  for (int c = 0; c < m_free_count; ++c) m_diagonal_slots[static_cast<size_t>(c)] = slot(c, c);
}

int TriangleAssembly::slot(int row, int column) const {
  const auto begin = m_row_indices.begin() + m_column_starts[static_cast<size_t>(column)];
  const auto end = m_row_indices.begin() + m_column_starts[static_cast<size_t>(column) + 1];
  const auto found = std::lower_bound(begin, end, row);
  if (found == end || *found != row) return -1;
  return static_cast<int>(found - m_row_indices.begin());
}

void TriangleAssembly::set_zero() { std::fill(m_values.begin(), m_values.end(), 0.0); }

void TriangleAssembly::add(int face, const Matrix9d& block) {
  const int* slots = &m_element_slots[static_cast<size_t>(face) * 81];
  const double* entries = block.data();  // column-major: entry (l, k) at l + 9 k
  for (int i = 0; i < 81; ++i)
    if (slots[i] >= 0) m_values[static_cast<size_t>(slots[i])] += entries[i];
}

void TriangleAssembly::add_hinge(int hinge, const Matrix12d& block) {
  const int* slots = &m_hinge_slots.at(static_cast<size_t>(hinge) * 144);
  const double* entries = block.data();
  for (int i = 0; i < 144; ++i)
    if (slots[i] >= 0) m_values[static_cast<size_t>(slots[i])] += entries[i];
}

void TriangleAssembly::add_block(const std::vector<int>& coordinates, const Eigen::MatrixXd& block) {
  const int size = static_cast<int>(coordinates.size());
  if (block.rows() != size || block.cols() != size)
    throw std::invalid_argument("TriangleAssembly::add_block: the block does not match its coordinates");
  for (int k = 0; k < size; ++k) {
    const int col = m_free_index[static_cast<size_t>(coordinates[static_cast<size_t>(k)])];
    if (col < 0) continue;
    for (int l = 0; l < size; ++l) {
      const int row = m_free_index[static_cast<size_t>(coordinates[static_cast<size_t>(l)])];
      if (row < 0 || row > col) continue;
      const int s = slot(row, col);
      if (s < 0) throw std::out_of_range("TriangleAssembly::add_block: an entry outside the pattern");
      m_values[static_cast<size_t>(s)] += block(l, k);
    }
  }
}

void TriangleAssembly::add_entry(int row_coordinate, int column_coordinate, double value) {
  const int row = m_free_index[static_cast<size_t>(row_coordinate)];
  const int col = m_free_index[static_cast<size_t>(column_coordinate)];
  if (row < 0 || col < 0 || row > col) return;
  const int s = slot(row, col);
  if (s < 0) throw std::out_of_range("TriangleAssembly::add_entry: an entry outside the pattern");
  m_values[static_cast<size_t>(s)] += value;
}

void TriangleAssembly::add_to_diagonal(double value) {
  for (int s : m_diagonal_slots) m_values[static_cast<size_t>(s)] += value;
}

double TriangleAssembly::mean_abs_diagonal() const {
  if (m_diagonal_slots.empty()) return 0.0;
  double sum = 0.0;
  for (int s : m_diagonal_slots) sum += std::abs(m_values[static_cast<size_t>(s)]);
  return sum / static_cast<double>(m_diagonal_slots.size());
}

Eigen::VectorXd TriangleAssembly::restrict(const Eigen::VectorXd& full) const {
  Eigen::VectorXd free(m_free_count);
  for (int i = 0; i < m_free_count; ++i) free[i] = full[m_free_to_coordinate[static_cast<size_t>(i)]];
  return free;
}

Eigen::VectorXd TriangleAssembly::extend(const Eigen::VectorXd& free) const {
  Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m_free_index.size()));
  for (int i = 0; i < m_free_count; ++i) full[m_free_to_coordinate[static_cast<size_t>(i)]] = free[i];
  return full;
}

Eigen::VectorXd TriangleAssembly::multiply(const Eigen::VectorXd& x) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(m_free_count);
  for (int col = 0; col < m_free_count; ++col) {
    for (int s = m_column_starts[static_cast<size_t>(col)]; s < m_column_starts[static_cast<size_t>(col) + 1]; ++s) {
      const int row = m_row_indices[static_cast<size_t>(s)];
      const double v = m_values[static_cast<size_t>(s)];
      y[row] += v * x[col];
      if (row != col) y[col] += v * x[row];
    }
  }
  return y;
}

}  // namespace balloon::fem

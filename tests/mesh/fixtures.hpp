#pragma once
/// \file
/// Test meshes with analytically known properties, built independently of the code under test.

#include <simsr/mesh/poly_mesh.hpp>
#include <simsr/mesh/tet_mesh.hpp>
#include <simsr/mesh/tri_mesh.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace simsr::test {

/// Six times the signed volume via a 3×3 determinant (independent of the library's formula).
inline double det_volume6(const Points<>& V, const std::array<VIndex, 4>& t) {
  Eigen::Matrix3d M;
  for (int k = 0; k < 3; ++k) M.col(k) = (V.row(t[k + 1]) - V.row(t[0])).transpose();
  return M.determinant();
}

/// Grid of nx×ny×nz cubes of side h, each split into 6 tets around its main diagonal (Kuhn) or
/// into 5 tets (alternating with the cube's parity so neighbouring faces match). All tets
/// positively oriented. Vertex (i,j,k) has index i + (nx+1)(j + (ny+1)k).
inline TetMesh<> box_tets(int nx, int ny, int nz, double h = 1.0, Vec3<> origin = Vec3<>::Zero(), bool five = false) {
  TetMesh<> m;
  m.V.resize(Index(nx + 1) * (ny + 1) * (nz + 1), 3);
  auto id = [&](int i, int j, int k) { return VIndex(i + (nx + 1) * (j + (ny + 1) * k)); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.V.row(id(i, j, k)) = (origin + h * Vec3<>(i, j, k)).transpose();
  std::vector<std::array<VIndex, 4>> tets;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        VIndex c[8];
        for (int b = 0; b < 8; ++b) c[b] = id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
        std::vector<std::array<int, 4>> local;
        if (!five) {
          const int axes[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
          for (auto& a : axes) local.push_back({0, a[0], a[0] + a[1], 7});
        } else if ((i + j + k) % 2 == 0) {
          local = {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}};
        } else {
          local = {{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}};
        }
        for (auto& l : local) {
          std::array<VIndex, 4> t{c[l[0]], c[l[1]], c[l[2]], c[l[3]]};
          if (det_volume6(m.V, t) < 0) std::swap(t[2], t[3]);
          tets.push_back(t);
        }
      }
  m.T.resize(Index(tets.size()), 4);
  for (Index t = 0; t < m.T.rows(); ++t)
    for (int c = 0; c < 4; ++c) m.T(t, c) = tets[t][c];
  return m;
}

/// Number of boundary triangles of a box_tets grid: two per boundary square.
inline Index box_boundary_count(int nx, int ny, int nz) { return 4 * (Index(nx) * ny + Index(ny) * nz + Index(nz) * nx); }

/// Moves every vertex by a uniform random offset in [−amp, amp]³.
template <class Rng>
void jitter(Points<>& V, double amp, Rng& rng) {
  std::uniform_real_distribution<double> u(-amp, amp);
  for (Index i = 0; i < V.size(); ++i) V.data()[i] += u(rng);
}

/// Renumbers vertices by a random permutation (positions move along): a mesh's properties must not change.
template <class Rng, class Elements>
void shuffle_vertices(Points<>& V, Elements& E, Rng& rng) {
  std::vector<VIndex> p(static_cast<std::size_t>(V.rows()));
  std::iota(p.begin(), p.end(), 0);
  std::shuffle(p.begin(), p.end(), rng);
  Points<> W(V.rows(), 3);
  for (Index v = 0; v < V.rows(); ++v) W.row(p[v]) = V.row(v);
  V = W;
  for (Index i = 0; i < E.size(); ++i) E.data()[i] = p[E.data()[i]];
}

/// Random rotation matrix (uniform quaternion).
template <class Rng>
Mat3<> random_rotation(Rng& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

/// Icosahedron subdivided `level` times (midpoints projected), radius r, outward-oriented.
inline TriMesh<> icosphere(int level, double r = 1.0) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3<>> P = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<VIndex, 3>> F = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                          {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                          {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (auto& p : P) p.normalize();
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<VIndex, VIndex>, VIndex> mid;
    auto midpoint = [&](VIndex a, VIndex b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      P.push_back((P[a] + P[b]).normalized());
      return mid[key] = VIndex(P.size() - 1);
    };
    std::vector<std::array<VIndex, 3>> G;
    for (auto& f : F) {
      VIndex a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      G.insert(G.end(), {{f[0], a, c}, {f[1], b, a}, {f[2], c, b}, {a, b, c}});
    }
    F = G;
  }
  TriMesh<> m;
  m.V.resize(Index(P.size()), 3);
  for (Index i = 0; i < m.V.rows(); ++i) m.V.row(i) = r * P[i].transpose();
  m.F.resize(Index(F.size()), 3);
  for (Index i = 0; i < m.F.rows(); ++i)
    for (int c = 0; c < 3; ++c) m.F(i, c) = F[i][c];
  return m;
}

/// Planar n×n grid of unit squares in z = 0, each split into two triangles along a random diagonal; normals +z.
template <class Rng>
TriMesh<> grid_surface(int n, Rng& rng) {
  TriMesh<> m;
  m.V.resize(Index(n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.V.row(i + (n + 1) * j) << i, j, 0.0;
  m.F.resize(2 * Index(n) * n, 3);
  Index f = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const VIndex a = i + (n + 1) * j, b = a + 1, c = a + n + 1, d = c + 1;
      if (rng() & 1) {
        m.F.row(f++) << a, b, d;
        m.F.row(f++) << a, d, c;
      } else {
        m.F.row(f++) << a, b, c;
        m.F.row(f++) << b, d, c;
      }
    }
  return m;
}

/// Tiny OBJ reader for the tests only (v and f lines; f corners "i", "i/t", "i/t/n", 1-based).
inline PolyMesh<> load_obj_polygons(const std::string& path) {
  PolyMesh<> m;
  std::ifstream in(path);
  std::vector<double> xyz;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      double x, y, z;
      s >> x >> y >> z;
      xyz.insert(xyz.end(), {x, y, z});
    } else if (tag == "f") {
      std::vector<VIndex> corners;
      std::string c;
      while (s >> c) corners.push_back(VIndex(std::stol(c.substr(0, c.find('/'))) - 1));
      m.add_face(corners);
    }
  }
  m.V = Eigen::Map<const Points<>>(xyz.data(), Index(xyz.size() / 3), 3);
  return m;
}

}  // namespace simsr::test

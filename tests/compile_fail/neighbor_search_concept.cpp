// expect: This type is not a NeighborSearch: it must answer `query_into
// Must NOT compile: a search whose query takes no execution policy is not a
// neighbors::NeighborSearch, and the network's dynamic feature graph (a library template checked by
// the concept) says so in one sentence.
#include <simsr/nn/graph_features.hpp>

struct PolicylessSearch {
  using scalar_type = float;
  using point_matrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  void build(const point_matrix&) {}
  simsr::Index size() const { return 0; }
  simsr::Index dim() const { return 3; }
  simsr::neighbors::KnnResult<float> query(const point_matrix&, simsr::Index) const { return {}; }
};

int main() {
  simsr::nn::DynamicKnnGraph<float, PolicylessSearch> graph;
  (void)graph;
}

#include <doctest/doctest.h>

#include <simsr/mesh/generators.hpp>
#include <simsr/shell/mesh_autoencoder.hpp>

#include "../nn/gradient_check.hpp"

namespace shell_test_mesh_autoencoder {

using namespace simsr;
using namespace simsr::shell;
using nn::Matrix;

TEST_CASE("shell::MeshEncoder and MeshDecoder: shapes over a batch, finite-difference gradients, seq == omp") {
  std::mt19937_64 rng(61);
  nn::Rng init(62);
  const TriMesh<> sheet = square_sheet(1.0, 3);  // 16 vertices
  const Adjacency A = vertex_adjacency(sheet.F, sheet.V.rows());
  const MeshCodecOptions opt{.channels = 4, .latent = 5};
  {
    nn::ParameterStore<double> store;
    MeshEncoder<double> enc(store, "enc", A, opt, init);
    const Matrix<double> x = test::random_matrix(rng, 2 * 16, 9);
    Matrix<double> z;
    enc.forward(exec::seq, nn::Mode::train, x, z);
    CHECK(z.rows() == 2);
    CHECK(z.cols() == 5);
    // each batch item is encoded on its own
    Matrix<double> z0;
    enc.forward(exec::seq, nn::Mode::train, Matrix<double>(x.topRows(16)), z0);
    CHECK((z0.row(0) - z.row(0)).cwiseAbs().maxCoeff() < 1e-14);
    test::check_gradients(test::layer_gradient_check(enc, &store, x, nn::Mode::train, rng), 1e-6);
    test::check_seq_equals_omp(enc, &store, x, nn::Mode::train, rng);
  }
  nn::ParameterStore<double> store;
  MeshDecoder<double> dec(store, "dec", A, opt, init);
  const Matrix<double> z = test::random_matrix(rng, 2, 5);
  Matrix<double> f;
  dec.forward(exec::seq, nn::Mode::train, z, f);
  CHECK(f.rows() == 32);
  CHECK(f.cols() == 9);
  test::check_gradients(test::layer_gradient_check(dec, &store, z, nn::Mode::train, rng), 1e-6);
  test::check_seq_equals_omp(dec, &store, z, nn::Mode::train, rng);
}

}  // namespace shell_test_mesh_autoencoder

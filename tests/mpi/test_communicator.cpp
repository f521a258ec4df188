// simsr::mpi::Communicator on 2 ranks (mpirun -np 2): each collective against what every rank can
// compute by itself, MPI's failures as MpiError, bad arguments refused by name.
#include <doctest/doctest.h>

#include <simsr/mpi/communicator.hpp>

#include <string>
#include <vector>

#include "../support/error_of.hpp"

namespace mpi_test_communicator {

using namespace simsr;
using mpi::Communicator;

TEST_CASE("mpi::Communicator: rank, size, shard") {
  const Communicator c = Communicator::world();
  REQUIRE(c.size() >= 2);  // the suite runs under mpirun -np 2
  CHECK(c.rank() >= 0);
  CHECK(c.rank() < c.size());
  CHECK(c.is_root() == (c.rank() == 0));
  CHECK(c.shard().index == c.rank());
  CHECK(c.shard().count == c.size());
  const Communicator self = Communicator::self();
  CHECK(self.size() == 1);
  CHECK(self.rank() == 0);
}

TEST_CASE("mpi::Communicator: allgather of values, arrays of any length and strings, in rank order") {
  const Communicator c = Communicator::world();
  const std::vector<int> ranks = c.allgather(c.rank());
  REQUIRE(int(ranks.size()) == c.size());
  for (int r = 0; r < c.size(); ++r) CHECK(ranks[std::size_t(r)] == r);

  struct Pod {
    double x;
    std::int64_t n;
  };
  const auto pods = c.allgather(Pod{0.5 * c.rank(), 100 + c.rank()});
  for (int r = 0; r < c.size(); ++r) {
    CHECK(pods[std::size_t(r)].x == 0.5 * r);
    CHECK(pods[std::size_t(r)].n == 100 + r);
  }

  // rank r sends 3r values (rank 0 none): lengths differ and one is empty
  std::vector<double> mine;
  for (int k = 0; k < 3 * c.rank(); ++k) mine.push_back(1000.0 * c.rank() + k + 0.25);
  const auto arrays = c.allgather(mine);
  REQUIRE(int(arrays.size()) == c.size());
  for (int r = 0; r < c.size(); ++r) {
    REQUIRE(arrays[std::size_t(r)].size() == std::size_t(3 * r));
    for (int k = 0; k < 3 * r; ++k) CHECK(arrays[std::size_t(r)][std::size_t(k)] == 1000.0 * r + k + 0.25);
  }

  const auto words = c.allgather(std::string(std::size_t(c.rank()) + 1, char('a' + c.rank())));
  for (int r = 0; r < c.size(); ++r) CHECK(words[std::size_t(r)] == std::string(std::size_t(r) + 1, char('a' + r)));
}

TEST_CASE("mpi::Communicator: broadcast from any root; any() is a logical or") {
  const Communicator c = Communicator::world();
  for (int root = 0; root < c.size(); ++root) {
    CHECK(c.broadcast(std::string("from ") + std::to_string(c.rank()), root) == "from " + std::to_string(root));
    CHECK(c.broadcast(7.5 * c.rank(), root) == 7.5 * root);
  }
  CHECK(c.broadcast(std::string(), 0).empty());
  CHECK(c.any(c.rank() == c.size() - 1));
  CHECK_FALSE(c.any(false));
  CHECK(c.any(true));
  c.barrier();
}

TEST_CASE("mpi::Communicator: a root outside the ranks is refused; MPI's own failures are MpiError naming the call") {
  const Communicator c = Communicator::world();
  CHECK(test::typed_error_of<ArgumentError>([&] { c.broadcast(std::string("x"), c.size()); }) ==
        "mpi::Communicator::broadcast: root " + std::to_string(c.size()) + " of " + std::to_string(c.size()) + " ranks");
  CHECK(test::typed_error_of<ArgumentError>([&] { c.broadcast(1.0, -1); }).find("root -1") != std::string::npos);
  const std::string e = test::typed_error_of<mpi::MpiError>([] { Communicator bad(MPI_COMM_NULL); });
  CHECK(e.find("mpi: MPI_Comm_rank failed (error ") == 0);
}

TEST_CASE("mpi::launched_by_mpirun: true under mpirun") { CHECK(mpi::launched_by_mpirun()); }

}  // namespace mpi_test_communicator

#pragma once
/// \file
/// The ranks of a communicator as an nn::BatchGroup: data-parallel training (issue #16) over MPI.
///
///     mpi::MpiBatchGroup group(comm);
///     nn::TrainerOptions o;  o.group = &group;     // each rank: its block of every global batch
///     nn::Trainer<float> trainer(net, faces, frames, o);
///
/// Every sum over a batch is an MPI_Allgatherv of per-item partials followed by the same ordered
/// sum on every rank (nn/batch_split.hpp says why not MPI_Allreduce), so the run equals the
/// single-process run bit for bit, in float and in double, whatever the number of ranks.

#include <vector>

#include "../nn/batch_split.hpp"
#include "communicator.hpp"

namespace simsr::mpi {

class MpiBatchGroup final : public nn::BatchGroup {
 public:
  /// `comm` (not owned) must outlive the group; every rank of it takes part in every batch.
  explicit MpiBatchGroup(const Communicator& comm) : comm_(&comm) {}

  int rank() const override { return comm_->rank(); }
  int size() const override { return comm_->size(); }

  void allgather_bytes(const void* mine, const std::vector<std::size_t>& bytes, void* all) override { comm_->allgather_bytes(mine, bytes, all); }

 private:
  const Communicator* comm_;
};

}  // namespace simsr::mpi

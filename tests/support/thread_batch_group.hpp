#pragma once
/// \file
/// R "ranks" as threads of one process for nn::BatchGroup: data-parallel training tested without
/// MPI (and under the sanitizers). Every member's allgather_bytes meets the others at a barrier.

#include <simsr/nn/batch_split.hpp>

#include <barrier>
#include <cstring>
#include <functional>
#include <thread>
#include <vector>

namespace simsr::test {

class ThreadBatchGroups {
 public:
  explicit ThreadBatchGroups(int ranks) : barrier_(ranks), mine_(std::size_t(ranks)) {
    for (int r = 0; r < ranks; ++r) members_.emplace_back(*this, r);
  }
  ThreadBatchGroups(const ThreadBatchGroups&) = delete;
  ThreadBatchGroups& operator=(const ThreadBatchGroups&) = delete;

  int size() const { return int(members_.size()); }
  nn::BatchGroup& member(int rank) { return members_.at(std::size_t(rank)); }

  /// Runs body(rank, group) on one thread per rank and waits for all; the first exception of any
  /// rank is rethrown (a rank that throws mid-collective would leave the others waiting: the
  /// bodies must throw, if at all, before their first collective or at the same point on all).
  void run(const std::function<void(int, nn::BatchGroup&)>& body) {
    std::vector<std::exception_ptr> errors(members_.size());
    std::vector<std::thread> threads;
    for (int r = 0; r < size(); ++r)
      threads.emplace_back([&, r] {
        try {
          body(r, member(r));
        } catch (...) {
          errors[std::size_t(r)] = std::current_exception();
        }
      });
    for (auto& t : threads) t.join();
    for (auto& e : errors)
      if (e) std::rethrow_exception(e);
  }

 private:
  class Member : public nn::BatchGroup {
   public:
    Member(ThreadBatchGroups& g, int rank) : g_(&g), rank_(rank) {}
    int rank() const override { return rank_; }
    int size() const override { return g_->size(); }
    void allgather_bytes(const void* mine, const std::vector<std::size_t>& bytes, void* all) override {
      g_->mine_[std::size_t(rank_)] = mine;
      g_->barrier_.arrive_and_wait();
      auto* out = static_cast<unsigned char*>(all);
      for (std::size_t r = 0; r < bytes.size(); ++r) {
        if (bytes[r]) std::memcpy(out, g_->mine_[r], bytes[r]);
        out += bytes[r];
      }
      g_->barrier_.arrive_and_wait();  // nobody's buffer changes before everyone has copied
    }

   private:
    ThreadBatchGroups* g_;
    int rank_;
  };

  std::barrier<> barrier_;
  std::vector<const void*> mine_;
  std::vector<Member> members_;
};

}  // namespace simsr::test

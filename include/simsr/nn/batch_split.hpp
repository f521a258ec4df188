#pragma once
/// \file
/// Data-parallel training (issue #16): the items of every global batch split among processes, and
/// every sum over the batch's rows taken in one order that does not depend on the split.
///
///     nn::BatchSplit split(&group);     // group: an nn::BatchGroup (mpi::MpiBatchGroup, or nullptr: one process)
///     net.set_batch_split(&split);      // the layers whose rows are batch rows take part
///     split.set_batch(32);              // this step's global batch: this rank holds items [first(), first() + count())
///
/// Why the results do not depend on the number of processes: with a split set, every layer cuts
/// its rows into chunks aligned to the batch items (the same chunks of an item on any rank), sums
/// over rows into one partial per item (the same bits on any rank), and adds the partials of all
/// items in global item order (BatchSplit::sum_items: on R > 1 ranks after an allgather of the
/// partials). A GEMM's rounding depends on where a row sits in its block, so the forward products
/// are chunked the same way. MPI_Allreduce would send less but promises no order; allgather of
/// per-item partials costs items·width per sum instead of width (the README's scaling model).
/// Without a split (nullptr) every layer runs as before, chunked over all its rows.

#include <algorithm>
#include <cstring>
#include <atomic>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "../core/error.hpp"
#include "../core/work_shard.hpp"
#include "tensor.hpp"

namespace simsr::nn {

/// The processes that share each global batch, one rank each: what a BatchSplit needs of a
/// communicator (simsr::mpi::MpiBatchGroup is the MPI one). Called by every rank in the same order.
class BatchGroup {
 public:
  virtual ~BatchGroup() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// `all` ← every rank's `bytes[r]` bytes, concatenated in rank order; `mine` holds bytes[rank()].
  virtual void allgather_bytes(const void* mine, const std::vector<std::size_t>& bytes, void* all) = 0;
};

class BatchSplit {
 public:
  /// `group`: the ranks sharing each batch (not owned), or nullptr for one process.
  explicit BatchSplit(BatchGroup* group = nullptr) : group_(group) {
    if (group_ && (group_->size() < 1 || group_->rank() < 0 || group_->rank() >= group_->size()))
      throw ArgumentError("nn::BatchSplit: rank " + std::to_string(group_->rank()) + " of " + std::to_string(group_->size()));
  }

  int rank() const { return group_ ? group_->rank() : 0; }
  int size() const { return group_ ? group_->size() : 1; }
  bool is_root() const { return rank() == 0; }
  BatchGroup* group() const { return group_; }

  /// This step's global batch of `items` items; this rank takes its block (WorkShard's partition).
  /// ArgumentError for fewer items than ranks (a rank without rows has no batch statistics).
  void set_batch(Index items) {
    if (items < size())
      throw ArgumentError("nn::BatchSplit: a batch of " + std::to_string(items) + " items cannot be split over " + std::to_string(size()) +
                          " ranks (each needs at least one)");
    items_ = items;
    item_rows_.clear();
    std::tie(first_, last_) = WorkShard{rank(), size()}.range(items);
    counts_.resize(std::size_t(size()));
    for (int r = 0; r < size(); ++r) {
      const auto [b, e] = WorkShard{r, size()}.range(items);
      counts_[std::size_t(r)] = e - b;
    }
  }

  /// Items of unequal sizes: item i is `rows[i]` rows of one fixed tensor (the upsampling's
  /// queries, in groups of HR vertices); this rank takes its block of the items, the contiguous
  /// rows [local_row_begin(), + local_rows()). ArgumentError for fewer items than ranks or an
  /// empty item.
  void set_items(const std::vector<Index>& rows) {
    set_batch(Index(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (rows[i] < 1) throw ArgumentError("nn::BatchSplit::set_items: item " + std::to_string(i) + " has no rows");
    item_rows_ = rows;
    local_offsets_.assign(1, 0);
    row_begin_ = 0;
    for (Index i = 0; i < first_; ++i) row_begin_ += rows[std::size_t(i)];
    for (Index i = first_; i < last_; ++i) local_offsets_.push_back(local_offsets_.back() + rows[std::size_t(i)]);
    total_rows_ = 0;
    min_rows_ = rows.empty() ? 0 : rows[0];
    for (Index r : rows) total_rows_ += r, min_rows_ = std::min(min_rows_, r);
    rank_rows_.assign(std::size_t(size()), 0);
    Index item = 0;
    for (int r = 0; r < size(); ++r)
      for (Index c = 0; c < counts_[std::size_t(r)]; ++c) rank_rows_[std::size_t(r)] += rows[std::size_t(item++)];
  }
  /// Unequal items (set_items): this rank's first row and its rows.
  Index local_row_begin() const { return row_begin_; }
  Index local_rows() const { return local_offsets_.empty() ? 0 : local_offsets_.back(); }
  /// Items of the global batch, the first of this rank's, how many this rank holds.
  Index items() const { return items_; }
  Index first() const { return first_; }
  Index count() const { return last_ - first_; }

  /// Rows per item of a tensor of `rows` local rows; ShapeError unless rows = count()·k, k ≥ 1.
  Index rows_per_item(Index rows, const std::string& where) const {
    if (items_ < 1) throw ArgumentError(where + ": the batch split has no batch yet (BatchSplit::set_batch)");
    if (rows < count() || rows % count())
      throw ShapeError(where + ": rows of " + std::to_string(count()) + " local batch items", {count(), -1}, {rows, -1});
    return rows / count();
  }

  /// Rows of the whole batch for a tensor of `rows` local rows (BatchNorm's count).
  Index total_rows(Index rows, const std::string& where) const {
    if (item_rows_.empty()) return rows_per_item(rows, where) * items_;
    if (rows != local_rows()) throw ShapeError(where + ": rows of this rank's items", {local_rows(), -1}, {rows, -1});
    return total_rows_;
  }

  /// Item-aligned chunks of `rows` local rows: each item cut into k = ⌈target / items()⌉ chunks
  /// (at most the smallest item's rows), the same on every rank. chunk c is item c / k's
  /// sub-chunk c % k; max_size is the largest chunk of any rank (GEMM buffers are sized by it,
  /// and their rounding depends on the size).
  struct Chunks {
    Index rows_per_item = 0, per_item = 1, items = 0, largest = 0;
    const Index* offsets = nullptr;  ///< unequal items: the local items' row offsets (items + 1)
    Index count() const { return items * per_item; }
    std::pair<Index, Index> range(Index c) const {
      const Index item = c / per_item;
      const Index base = offsets ? offsets[item] : item * rows_per_item, n = offsets ? offsets[item + 1] - base : rows_per_item;
      const auto [b, e] = exec::chunk_range(n, per_item, c % per_item);
      return {base + b, base + e};
    }
    Index max_size() const { return largest; }
  };
  Chunks chunks(Index rows, Index target, const std::string& where) const {
    Chunks c;
    c.items = count();
    if (item_rows_.empty()) {
      c.rows_per_item = rows_per_item(rows, where);
      c.per_item = std::clamp<Index>((target + items_ - 1) / items_, 1, std::max<Index>(1, c.rows_per_item));
      c.largest = exec::max_chunk_size(c.rows_per_item, c.per_item);
      return c;
    }
    total_rows(rows, where);  // checks the rows
    c.offsets = local_offsets_.data();
    c.per_item = std::clamp<Index>((target + items_ - 1) / items_, 1, std::max<Index>(1, min_rows_));
    for (Index r : item_rows_) c.largest = std::max(c.largest, exec::max_chunk_size(r, c.per_item));
    return c;
  }

  /// out[0, width) += partial of item 0, then of item 1, … of the whole global batch, in order,
  /// where `local` holds this rank's count() partials (count()×width, row-major). Every rank
  /// ends with the same `out`.
  template <class T>
  void sum_items(const T* local, Index width, T* out) {
    static_assert(std::is_trivially_copyable_v<T>);
    const T* all = gather(local, width);
    for (Index i = 0; i < items_; ++i)
      for (Index j = 0; j < width; ++j) out[j] += all[i * width + j];
  }

  /// All items' partials (items()×width, global item order), this rank's from `local`. The
  /// pointer is valid until the next call.
  template <class T>
  const T* gather(const T* local, Index width) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (size() == 1) return local;
    std::vector<std::size_t> bytes(counts_.size());
    for (std::size_t r = 0; r < counts_.size(); ++r) bytes[r] = std::size_t(counts_[r] * width) * sizeof(T);
    return exchange<T>(local, bytes, items_ * width);
  }

  /// Unequal items (set_items): every rank's rows (local_rows() × width, row-major) concatenated
  /// in item order, total rows × width. The pointer is valid until the next call.
  template <class T>
  const T* gather_rows(const T* local, Index width) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (item_rows_.empty()) throw ArgumentError("nn::BatchSplit::gather_rows: needs items of given rows (set_items)");
    if (size() == 1) return local;
    std::vector<std::size_t> bytes(rank_rows_.size());
    for (std::size_t r = 0; r < bytes.size(); ++r) bytes[r] = std::size_t(rank_rows_[r] * width) * sizeof(T);
    return exchange<T>(local, bytes, total_rows_ * width);
  }

  /// Collectives made and bytes this rank received from the others so far (the communication
  /// volume of the README's scaling model); 0 on one process.
  std::int64_t gathers() const { return gathers_; }
  std::int64_t bytes_received() const { return bytes_received_; }

 private:
  template <class T>
  const T* exchange(const T* local, const std::vector<std::size_t>& bytes, Index total) {
    scratch_.resize(std::size_t(total) * sizeof(T) / sizeof(double) + 1);
    group_->allgather_bytes(local, bytes, scratch_.data());
    ++gathers_;
    for (std::size_t r = 0; r < bytes.size(); ++r) bytes_received_ += r == std::size_t(rank()) ? 0 : bytes[r];
    return reinterpret_cast<const T*>(scratch_.data());
  }

  BatchGroup* group_ = nullptr;
  std::int64_t gathers_ = 0, bytes_received_ = 0;
  std::vector<Index> item_rows_, local_offsets_, rank_rows_;  ///< unequal items (set_items) only
  Index row_begin_ = 0, total_rows_ = 0, min_rows_ = 0;
  Index items_ = 0, first_ = 0, last_ = 0;
  std::vector<Index> counts_;
  std::vector<double> scratch_;  ///< double-aligned bytes of the last gather
};

namespace detail {
/// The row chunks a layer loops over: item-aligned under a split, else `target` chunks of all rows.
struct RowChunks {
  BatchSplit::Chunks items;
  Index rows = 0, plain = 0;
  bool split = false;
  Index count() const { return split ? items.count() : plain; }
  std::pair<Index, Index> range(Index c) const { return split ? items.range(c) : exec::chunk_range(rows, plain, c); }
  Index max_size() const { return split ? items.max_size() : exec::max_chunk_size(rows, plain); }
};
inline RowChunks row_chunks(const BatchSplit* split, Index rows, Index target, const std::string& where) {
  RowChunks r;
  r.rows = rows;
  r.split = split != nullptr;
  if (r.split)
    r.items = split->chunks(rows, target, where);
  else
    r.plain = exec::chunk_count(rows, target);
  return r;
}
/// body(worker, chunk, begin, end) for every chunk; worker w takes chunks w, w + workers, …
template <class Policy, class Body>
void for_row_chunks(Policy policy, const RowChunks& chunks, Index workers, Body&& body) {
  exec::parallel_for(policy, workers, [&](Index w) {
    for (Index c = w; c < chunks.count(); c += workers) {
      const auto [b, e] = chunks.range(c);
      body(w, c, b, e);
    }
  });
}
/// The same chunks handed out one at a time to whichever worker is free (only who computes
/// which chunk changes, never the arithmetic): both threads stay busy on a loaded machine.
template <class Policy, class Body>
void for_row_chunks_dynamic(Policy policy, const RowChunks& chunks, Index workers, Body&& body) {
  if (workers <= 1) {
    for_row_chunks(policy, chunks, workers, body);
    return;
  }
  std::atomic<Index> next{0};
  exec::parallel_for(policy, workers, [&](Index w) {
    for (Index c; (c = next.fetch_add(1, std::memory_order_relaxed)) < chunks.count();) {
      const auto [b, e] = chunks.range(c);
      body(w, c, b, e);
    }
  });
}
/// Folds the per-chunk partials (rows of `parts`, chunks.count() × width, row-major) into one
/// per item in place (rows 0 … items − 1, each the sum of its sub-chunks in order): what
/// BatchSplit::gather takes. Nothing to do with one chunk per item.
template <class T>
void fold_item_partials(const RowChunks& chunks, T* parts, Index width) {
  const Index k = chunks.items.per_item;
  if (k == 1) return;
  for (Index i = 0; i < chunks.items.items; ++i) {
    T* dst = parts + i * width;
    const T* first = parts + i * k * width;
    if (dst != first) std::memcpy(dst, first, std::size_t(width) * sizeof(T));
    for (Index s = 1; s < k; ++s) {
      const T* src = parts + (i * k + s) * width;
      for (Index j = 0; j < width; ++j) dst[j] += src[j];
    }
  }
}
}  // namespace detail

}  // namespace simsr::nn

#pragma once
/// \file
/// NumPy `.npz` archives (zip files of .npy members, as `np.savez` / `np.savez_compressed` write
/// them) through libzip: read from a path or from memory, all members or lazily one at a time;
/// write stored or deflate-compressed.
///
///     simsr::io::NpzReader z(data / "bunny/train_frames.npz");   // reads the directory only
///     const auto low = z.read("lowres");                          // decompresses one member
///     simsr::Points<double> x0 = low.frame_points(0);             // 1747×3
///
///     simsr::io::NpzArrays out;
///     out["error"] = simsr::io::make_npy(err);                    // Eigen or xtensor
///     simsr::io::write_npz("report.npz", out, simsr::io::NpzCompression::Deflate);
///
/// Names are shown as numpy shows them (without the `.npy` suffix); members not ending in `.npy`
/// are ignored. Hostile archives give simsr::ParseError("<archive>:<member>", 0, "byte <offset>: ...")
/// or ParseError("<archive>", 0, ...): the declared uncompressed size of a member is checked against
/// its compressed size (stored: equal; deflate: at most 1032:1, deflate's limit) and against the
/// .npy header before anything is allocated, CRC errors surface from libzip, and no data beyond the
/// declared size is accepted.

#include <zip.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "atomic_file.hpp"
#include "detail/zip_handle.hpp"
#include "npy.hpp"

namespace simsr::io {

/// Name → array map that keeps insertion (archive) order.
class NpzArrays {
 public:
  using value_type = std::pair<std::string, NpyArray>;

  std::size_t size() const { return items_.size(); }
  bool empty() const { return items_.empty(); }
  bool contains(std::string_view name) const { return find(name) != nullptr; }
  /// The array called `name`; ArgumentError when absent.
  const NpyArray& at(std::string_view name) const {
    if (const auto* a = find(name)) return *a;
    throw ArgumentError("npz: no array named '" + std::string(name) + "'");
  }
  NpyArray& at(std::string_view name) { return const_cast<NpyArray&>(std::as_const(*this).at(name)); }
  /// The array called `name`, appended (empty) when absent.
  NpyArray& operator[](std::string_view name) {
    if (auto* a = const_cast<NpyArray*>(find(name))) return *a;
    items_.emplace_back(std::string(name), NpyArray{});
    return items_.back().second;
  }
  void insert_or_assign(std::string name, NpyArray a) { (*this)[name] = std::move(a); }
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const auto& [k, v] : items_) n.push_back(k);
    return n;
  }
  auto begin() const { return items_.begin(); }
  auto end() const { return items_.end(); }
  auto begin() { return items_.begin(); }
  auto end() { return items_.end(); }

 private:
  const NpyArray* find(std::string_view name) const {
    for (const auto& [k, v] : items_)
      if (k == name) return &v;
    return nullptr;
  }
  std::vector<value_type> items_;
};

/// How write_npz stores members: as `np.savez` (stored) or `np.savez_compressed` (deflate).
enum class NpzCompression { Stored, Deflate };

/// Lazy .npz reader: the constructor reads and validates the zip directory; read() decompresses and
/// parses one member. Not thread-safe (libzip archives are not); use one reader per thread.
class NpzReader {
 public:
  /// Opens an archive file.
  explicit NpzReader(const std::filesystem::path& path) : source_(path.string()) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) throw ParseError(source_, 0, "cannot open archive: " + ec.message());
    archive_size_ = size;
    if (size == 0) throw ParseError(source_, 0, "cannot open zip archive: empty file");
    int code = 0;
    zip_ = detail::ZipPtr(zip_open(source_.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &code));
    if (!zip_) throw ParseError(source_, 0, "cannot open zip archive: " + detail::zip_error_text(code));
    index();
  }

  /// Opens an archive held in memory; the bytes are copied (or moved in with the vector overload).
  NpzReader(const void* data, std::size_t size, std::string source = "<memory>")
      : NpzReader(std::vector<std::byte>(static_cast<const std::byte*>(data), static_cast<const std::byte*>(data) + size),
                  std::move(source)) {}

  explicit NpzReader(std::vector<std::byte> data, std::string source = "<memory>")
      : buffer_(std::make_unique<std::vector<std::byte>>(std::move(data))), source_(std::move(source)) {
    archive_size_ = buffer_->size();
    if (archive_size_ == 0) throw ParseError(source_, 0, "cannot open zip archive: empty file");
    zip_error_t err;
    zip_error_init(&err);
    detail::ZipSourcePtr src(zip_source_buffer_create(buffer_->data(), buffer_->size(), 0, &err));
    if (!src) {
      const std::string msg = detail::zip_error_text(&err);
      zip_error_fini(&err);
      throw ParseError(source_, 0, "cannot create zip source: " + msg);
    }
    zip_ = detail::ZipPtr(zip_open_from_source(src.get(), ZIP_RDONLY | ZIP_CHECKCONS, &err));
    if (!zip_) {
      const std::string msg = detail::zip_error_text(&err);
      zip_error_fini(&err);
      throw ParseError(source_, 0, "cannot open zip archive: " + msg);
    }
    (void)src.release();  // owned by the archive now
    zip_error_fini(&err);
    index();
  }

  NpzReader(NpzReader&&) noexcept = default;
  NpzReader& operator=(NpzReader&&) noexcept = default;

  /// Array names in archive order (member names without `.npy`).
  const std::vector<std::string>& names() const { return names_; }
  bool contains(std::string_view name) const { return position(name) >= 0; }
  const std::string& source() const { return source_; }

  /// Largest uncompressed member read() accepts (default 16 GiB); larger ones give ParseError
  /// before anything is allocated.
  void set_max_member_bytes(std::uint64_t n) { max_member_bytes_ = n; }
  std::uint64_t max_member_bytes() const { return max_member_bytes_; }

  /// Reads and parses one member; ArgumentError when no member has that name.
  NpyArray read(std::string_view name) {
    const auto p = position(name);
    if (p < 0) throw ArgumentError(source_ + ": no array named '" + std::string(name) + "'");
    return read_member(entries_[static_cast<std::size_t>(p)], names_[static_cast<std::size_t>(p)]);
  }

  /// Reads every member, in archive order.
  NpzArrays read_all() {
    NpzArrays out;
    for (std::size_t i = 0; i < names_.size(); ++i) out.insert_or_assign(names_[i], read_member(entries_[i], names_[i]));
    return out;
  }

 private:
  std::ptrdiff_t position(std::string_view name) const {
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (names_[i] == name) return static_cast<std::ptrdiff_t>(i);
    return -1;
  }

  void index() {
    if (archive_size_ == 0) throw ParseError(source_, 0, "cannot open zip archive: empty file");
    const zip_int64_t n = zip_get_num_entries(zip_.get(), 0);
    if (n < 0) throw ParseError(source_, 0, "cannot read the zip directory");
    for (zip_int64_t i = 0; i < n; ++i) {
      const char* raw = zip_get_name(zip_.get(), static_cast<zip_uint64_t>(i), 0);
      if (!raw) throw ParseError(source_, 0, "zip entry " + std::to_string(i) + ": unreadable name");
      const std::string member(raw);
      if (member.size() < 4 || member.compare(member.size() - 4, 4, ".npy") != 0) continue;
      std::string name = member.substr(0, member.size() - 4);
      if (contains(name)) throw ParseError(source_, 0, "member '" + member + "' appears twice");
      names_.push_back(std::move(name));
      entries_.push_back(static_cast<zip_uint64_t>(i));
    }
  }

  NpyArray read_member(zip_uint64_t entry, const std::string& name) {
    const std::string where = source_ + ":" + name + ".npy";
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(zip_.get(), entry, 0, &st) != 0)
      throw ParseError(where, 0, "cannot stat member: " + std::string(zip_strerror(zip_.get())));
    const zip_uint64_t need = ZIP_STAT_SIZE | ZIP_STAT_COMP_SIZE | ZIP_STAT_COMP_METHOD;
    if ((st.valid & need) != need) throw ParseError(where, 0, "member sizes unknown");
    if ((st.valid & ZIP_STAT_ENCRYPTION_METHOD) && st.encryption_method != ZIP_EM_NONE)
      throw ParseError(where, 0, "encrypted members are not supported");
    if (st.comp_method != ZIP_CM_STORE && st.comp_method != ZIP_CM_DEFLATE)
      throw ParseError(where, 0, "unsupported compression method " + std::to_string(st.comp_method));
    if (st.comp_size > archive_size_)
      throw ParseError(where, 0, "compressed size " + std::to_string(st.comp_size) + " exceeds the archive size " +
                                     std::to_string(archive_size_));
    if (st.comp_method == ZIP_CM_STORE && st.size != st.comp_size)
      throw ParseError(where, 0, "stored member declares " + std::to_string(st.size) + " bytes but holds " +
                                     std::to_string(st.comp_size));
    if (st.comp_method == ZIP_CM_DEFLATE && st.size / 1032 > st.comp_size + 1)
      throw ParseError(where, 0, "declared size " + std::to_string(st.size) + " is impossible for " +
                                     std::to_string(st.comp_size) + " deflated bytes");
    if (st.size > max_member_bytes_)
      throw ParseError(where, 0, "declared size " + std::to_string(st.size) + " exceeds the limit of " +
                                     std::to_string(max_member_bytes_) + " bytes");
    detail::ZipFilePtr f(zip_fopen_index(zip_.get(), entry, 0));
    if (!f) throw ParseError(where, 0, "cannot open member: " + std::string(zip_strerror(zip_.get())));
    std::uint64_t pos = 0;
    auto read = [&](void* dst, std::size_t n) -> std::size_t {
      std::size_t got = 0;
      while (got < n) {
        const zip_int64_t r = zip_fread(f.get(), static_cast<char*>(dst) + got, n - got);
        if (r < 0)
          throw ParseError(where, 0, "byte " + std::to_string(pos + got) + ": " + zip_file_strerror(f.get()));
        if (r == 0) break;
        got += static_cast<std::size_t>(r);
      }
      pos += got;
      return got;
    };
    NpyArray a = detail::npy_read_stream(read, st.size, where);
    // Reading to the end makes libzip verify the CRC; data beyond the declared size is an error.
    char extra;
    if (read(&extra, 1) != 0)
      throw ParseError(where, 0, "byte " + std::to_string(st.size) + ": member holds more data than its declared size");
    return a;
  }

  std::unique_ptr<std::vector<std::byte>> buffer_;  // memory archives: the bytes libzip reads
  detail::ZipPtr zip_;
  std::string source_;
  std::uint64_t archive_size_ = 0;
  std::uint64_t max_member_bytes_ = std::uint64_t{1} << 34;
  std::vector<std::string> names_;
  std::vector<zip_uint64_t> entries_;
};

/// Reads every array of an .npz file.
inline NpzArrays read_npz(const std::filesystem::path& path) { return NpzReader(path).read_all(); }

/// Reads every array of an .npz held in memory.
inline NpzArrays read_npz_buffer(const void* data, std::size_t size, const std::string& source = "<memory>") {
  return NpzReader(data, size, source).read_all();
}

namespace detail {

/// Adds every array as `<name>.npy`; `hold` keeps the serialized bytes alive until zip_close.
inline void npz_add_members(zip_t* z, const NpzArrays& arrays, NpzCompression c, std::vector<std::vector<std::byte>>& hold,
                            const std::string& where) {
  for (const auto& [name, array] : arrays) {
    if (name.empty()) throw ArgumentError(where + ": empty array name");
    hold.push_back(npy_bytes(array));
    const auto& b = hold.back();
    zip_source_t* src = zip_source_buffer(z, b.data(), b.size(), 0);
    if (!src) throw ParseError(where, 0, "cannot create zip source: " + std::string(zip_strerror(z)));
    const std::string member = name + ".npy";
    const zip_int64_t idx = zip_file_add(z, member.c_str(), src, ZIP_FL_ENC_UTF_8);
    if (idx < 0) {
      zip_source_free(src);
      throw ParseError(where, 0, "cannot add member '" + member + "': " + zip_strerror(z));
    }
    if (zip_set_file_compression(z, static_cast<zip_uint64_t>(idx),
                                 c == NpzCompression::Deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0) != 0)
      throw ParseError(where, 0, "cannot set compression of '" + member + "': " + zip_strerror(z));
  }
}

/// The archive of `arrays` built in memory; errors name `where`.
inline std::vector<std::byte> npz_archive(const NpzArrays& arrays, NpzCompression compression, const std::string& where) {
  zip_error_t err;
  zip_error_init(&err);
  detail::ZipSourcePtr src(zip_source_buffer_create(nullptr, 0, 0, &err));
  if (!src) throw ParseError(where, 0, "cannot create zip source: " + detail::zip_error_text(&err));
  zip_source_keep(src.get());
  detail::ZipPtr z(zip_open_from_source(src.get(), ZIP_TRUNCATE, &err));
  if (!z) {
    const std::string msg = detail::zip_error_text(&err);
    zip_error_fini(&err);
    zip_source_free(src.get());  // drop the reference zip_open_from_source did not take
    throw ParseError(where, 0, "cannot create archive: " + msg);
  }
  zip_error_fini(&err);
  std::vector<std::vector<std::byte>> hold;
  detail::npz_add_members(z.get(), arrays, compression, hold, where);
  if (zip_close(z.get()) != 0) throw ParseError(where, 0, "cannot write archive: " + std::string(zip_strerror(z.get())));
  (void)z.release();
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_source_open(src.get()) != 0 || zip_source_stat(src.get(), &st) != 0 || !(st.valid & ZIP_STAT_SIZE))
    throw ParseError(where, 0, "cannot read back the archive");
  std::vector<std::byte> out(static_cast<std::size_t>(st.size));
  zip_uint64_t got = 0;
  while (got < st.size) {
    const zip_int64_t r = zip_source_read(src.get(), out.data() + got, st.size - got);
    if (r <= 0) break;
    got += static_cast<zip_uint64_t>(r);
  }
  zip_source_close(src.get());
  if (got != st.size) throw ParseError(where, 0, "cannot read back the archive");
  return out;
}

}  // namespace detail

/// Writes arrays to an .npz file, stored or deflate-compressed. The archive is built in memory and
/// written atomically (io/atomic_file.hpp): WriteError when it cannot be written, the previous file
/// then unchanged. (Not libzip's own temporary file and rename at zip_close: one path for every
/// output, special files such as /dev/full included, and one error type.)
inline void write_npz(const std::filesystem::path& path, const NpzArrays& arrays,
                      NpzCompression compression = NpzCompression::Stored) {
  write_file_atomic(path, detail::npz_archive(arrays, compression, path.string()));
}

/// Serializes arrays to .npz bytes in memory.
inline std::vector<std::byte> npz_bytes(const NpzArrays& arrays, NpzCompression compression = NpzCompression::Stored) {
  return detail::npz_archive(arrays, compression, "<memory>");
}

}  // namespace simsr::io

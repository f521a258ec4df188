#pragma once
/// \file
/// RAII and error-message helpers around libzip for the .npz reader and writer.

#include <zip.h>

#include <memory>
#include <string>

namespace simsr::io::detail {

struct ZipCloser {
  void operator()(zip_t* z) const noexcept {
    if (z) zip_discard(z);
  }
};
using ZipPtr = std::unique_ptr<zip_t, ZipCloser>;

struct ZipFileCloser {
  void operator()(zip_file_t* f) const noexcept {
    if (f) zip_fclose(f);
  }
};
using ZipFilePtr = std::unique_ptr<zip_file_t, ZipFileCloser>;

struct ZipSourceFree {
  void operator()(zip_source_t* s) const noexcept {
    if (s) zip_source_free(s);
  }
};
using ZipSourcePtr = std::unique_ptr<zip_source_t, ZipSourceFree>;

/// libzip's text for an error code.
inline std::string zip_error_text(int code) {
  zip_error_t e;
  zip_error_init_with_code(&e, code);
  std::string s = zip_error_strerror(&e);
  zip_error_fini(&e);
  return s;
}

inline std::string zip_error_text(zip_error_t* e) { return e ? std::string(zip_error_strerror(e)) : "unknown libzip error"; }

}  // namespace simsr::io::detail

// Replays every file of the given folders (or the given files) through LLVMFuzzerTestOneInput:
// the corpus of each fuzzer becomes a regression test in builds without libFuzzer.
#include <sys/resource.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <exception>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

// The file being replayed, for harnesses that hold seeds named valid_* to loading (npz_input.hpp).
extern "C" {
const char* simsr_fuzz_replay_file = nullptr;
}

static int replay(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string name = file.string();
  simsr_fuzz_replay_file = name.c_str();
  LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  return 1;
}

int main(int argc, char** argv) {
  // As libFuzzer's -rss_limit_mb/-malloc_limit_mb: an input that makes a reader ask for more than
  // 4 GiB is a finding (std::bad_alloc), not a machine pushed into its OOM killer.
  // Under ASan (whose shadow memory needs terabytes of address space) its allocator does the same:
  // ASAN_OPTIONS=max_allocation_size_mb=4096:allocator_may_return_null=1 (tests/fuzz/CMakeLists.txt).
#if defined(__has_feature)
#if !__has_feature(address_sanitizer)
#define SIMSR_REPLAY_LIMIT_ADDRESS_SPACE 1
#endif
#elif !defined(__SANITIZE_ADDRESS__)
#define SIMSR_REPLAY_LIMIT_ADDRESS_SPACE 1
#endif
#if defined(SIMSR_REPLAY_LIMIT_ADDRESS_SPACE)
  const rlimit limit{rlim_t{4} << 30, rlim_t{4} << 30};
  setrlimit(RLIMIT_AS, &limit);
#endif
  std::set_terminate([] {
    std::fprintf(stderr, "replay: uncaught exception while replaying %s\n", simsr_fuzz_replay_file ? simsr_fuzz_replay_file : "?");
    if (auto e = std::current_exception()) {
      try {
        std::rethrow_exception(e);
      } catch (const std::exception& x) {
        std::fprintf(stderr, "replay: %s\n", x.what());
      } catch (...) {
      }
    }
    std::abort();
  });
  int count = 0;
  for (int a = 1; a < argc; ++a) {
    const std::filesystem::path p(argv[a]);
    if (std::filesystem::is_directory(p)) {
      for (const auto& e : std::filesystem::recursive_directory_iterator(p))
        if (e.is_regular_file()) count += replay(e.path());
    } else {
      count += replay(p);
    }
  }
  std::printf("replayed %d inputs\n", count);
  return count > 0 ? 0 : 1;
}

// Replays every file of the given folders (or the given files) through LLVMFuzzerTestOneInput:
// the corpus of each fuzzer becomes a regression test. In the ASan build (clang, SIMSR_FUZZ_DRIVER)
// the same binary is also the libFuzzer fuzzer: `replay_<name> --fuzz [libFuzzer arguments]` hands
// over to libFuzzer's driver (scripts/fuzz.sh), so one build serves replays and fuzzing.
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
#if defined(SIMSR_FUZZ_DRIVER)
// libFuzzer's entry for programs with a main of their own (libclang_rt.fuzzer_no_main, LLVM >= 11).
extern "C" int LLVMFuzzerRunDriver(int* argc, char*** argv, int (*callback)(const std::uint8_t*, std::size_t));
#endif

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
  if (argc > 1 && std::string(argv[1]) == "--fuzz") {
#if defined(SIMSR_FUZZ_DRIVER)
    argv[1] = argv[0];  // libFuzzer sees "<program> [its arguments]"
    int fuzz_argc = argc - 1;
    char** fuzz_argv = argv + 1;
    return LLVMFuzzerRunDriver(&fuzz_argc, &fuzz_argv, LLVMFuzzerTestOneInput);
#else
    std::fprintf(stderr, "%s: built without libFuzzer; the ASan build has it (clang, SIMSR_SANITIZE=asan: scripts/fuzz.sh)\n", argv[0]);
    return 2;
#endif
  }
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

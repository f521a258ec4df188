// A canary for the sanitizer builds (SIMSR_SANITIZE=asan|tsan): each mode commits one error the
// sanitizer must report, so a sanitized suite that passes cannot be one whose sanitizer was never
// there (a flag lost, a runtime not linked, Archer not loaded). ctest expects the report's text.
//
//   sanitizer_canary overflow     heap-buffer-overflow            (ASan)
//   sanitizer_canary float-cast   outside the range of representable values  (UBSan float-cast-overflow)
//   sanitizer_canary race         ThreadSanitizer: data race      (TSan, inside an OpenMP region)
//   sanitizer_canary omp          a race-free OpenMP reduction; the Archer banner must appear
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {
volatile int sink = 0;
}

int main(int argc, char** argv) {
  const char* mode = argc > 1 ? argv[1] : "";
  if (std::strcmp(mode, "overflow") == 0) {
    std::vector<int>* v = new std::vector<int>(4, 1);
    sink = v->data()[4 + sink];
    delete v;
  } else if (std::strcmp(mode, "float-cast") == 0) {
    volatile double d = 1e300;
    sink = static_cast<int>(d);
  } else if (std::strcmp(mode, "race") == 0) {
    int shared = 0;
#pragma omp parallel num_threads(2)
    { shared += 1 + sink; }
    sink = shared;
  } else if (std::strcmp(mode, "omp") == 0) {
    std::vector<double> v(10000, 1.0);
    double sum = 0;
#pragma omp parallel for reduction(+ : sum) num_threads(2)
    for (int i = 0; i < 10000; ++i) sum += v[std::size_t(i)];
    if (sum != 10000) return 1;
  } else {
    std::fprintf(stderr, "usage: sanitizer_canary overflow|float-cast|race|omp\n");
    return 2;
  }
  std::printf("canary %s: no sanitizer report\n", mode);
  return 0;
}

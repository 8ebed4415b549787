// main() for a fuzz target where libFuzzer is not available (GCC builds, so also the asan build): runs
// LLVMFuzzerTestOneInput over pseudo-random inputs from a fixed seed, so that a failure reproduces, or over the
// files named on the command line (a crash input saved by a libFuzzer run).
//   usage: TARGET [inputs [max_len]]      TARGET FILE...
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

bool IsNumber(const char* text) {
  if (*text == '\0') return false;
  for (const char* c = text; *c; ++c)
    if (*c < '0' || *c > '9') return false;
  return true;
}

int RunFiles(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::ifstream file(argv[i], std::ios::binary);
    if (!file) {
      std::fprintf(stderr, "cannot read %s\n", argv[i]);
      return 2;
    }
    const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
    LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
  }
  std::printf("%d inputs from files run\n", argc - 1);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && !IsNumber(argv[1])) return RunFiles(argc, argv);
  const unsigned long inputs = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 1000;
  const size_t max_len = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 4096;
  std::mt19937_64 random(0x61737661ull);  // "asva": fixed, so that a failing input number reproduces
  std::vector<uint8_t> input;
  for (unsigned long n = 0; n < inputs; ++n) {
    // Mostly short inputs, where structure decisions vary most; now and then one up to max_len.
    const size_t len = (n % 8 == 7) ? random() % (max_len + 1) : random() % (max_len / 16 + 1);
    input.resize(len);
    for (auto& byte : input) byte = uint8_t(random());
    LLVMFuzzerTestOneInput(input.data(), input.size());
  }
  std::printf("%lu random inputs run (max_len %zu)\n", inputs, max_len);
  return 0;
}

// Runs a fuzz harness without libFuzzer (any compiler): on every file of the corpus folders
// given as arguments, then on `--random N` pseudo-random inputs from a fixed seed (`--seed S`,
// default 20261124; so the suite exercises the harness beyond its corpus, the same inputs on
// every run). A violated property aborts (non-zero status, the message on standard error).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv) {
  std::size_t files = 0, random_inputs = 0;
  std::uint64_t seed = 20261124;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--random" && i + 1 < argc) {
      random_inputs = std::strtoull(argv[++i], nullptr, 10);
      continue;
    }
    if (arg == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
      continue;
    }
    std::vector<std::filesystem::path> paths;
    for (const auto& entry : std::filesystem::directory_iterator(arg)) {
      if (entry.is_regular_file()) paths.push_back(entry.path());
    }
    std::sort(paths.begin(), paths.end());
    for (const auto& path : paths) {
      std::ifstream f(path, std::ios::binary);
      const std::vector<char> bytes((std::istreambuf_iterator<char>(f)),
                                    std::istreambuf_iterator<char>());
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      ++files;
    }
  }
  // KINETIC_FUZZ_SAVE=FILE: each random input is written to FILE before it runs.
  const char* save = std::getenv("KINETIC_FUZZ_SAVE");
  std::mt19937_64 rng(seed);
  std::vector<std::uint8_t> buffer;
  for (std::size_t k = 0; k < random_inputs; ++k) {
    buffer.resize(rng() % 256);
    for (std::uint8_t& b : buffer) b = static_cast<std::uint8_t>(rng());
    if (save != nullptr) {  // the input about to run, so that a failing one is kept
      std::ofstream(save, std::ios::binary)
          .write(reinterpret_cast<const char*>(buffer.data()),
                 static_cast<std::streamsize>(buffer.size()));
    }
    LLVMFuzzerTestOneInput(buffer.data(), buffer.size());
  }
  std::printf("%zu corpus files and %zu random inputs passed\n", files, random_inputs);
  return 0;
}

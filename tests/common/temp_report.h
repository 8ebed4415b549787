#pragma once
// A JSON-lines report file for tests: created empty in /tmp, removed at the end, read back line by line.
#include <unistd.h>

#include <catch2/catch_test_macros.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace asval_test_common {

struct TempReport {
  std::string path;
  TempReport() {
    char name[] = "/tmp/asval-report-XXXXXX";
    const int fd = mkstemp(name);
    REQUIRE(fd >= 0);
    close(fd);
    path = name;
  }
  ~TempReport() { std::remove(path.c_str()); }
  TempReport(const TempReport&) = delete;
  TempReport& operator=(const TempReport&) = delete;
  std::vector<std::string> Lines() const {
    std::ifstream in(path, std::ios::binary);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }
};

// The line with bytes outside printable ASCII as \xNN: Catch2's message printer asserts on some raw bytes.
inline std::string Printable(const std::string& line) {
  std::string out;
  for (unsigned char c : line) {
    if (c >= 0x20 && c < 0x7f) {
      out.push_back(static_cast<char>(c));
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out.append(hex);
    }
  }
  return out;
}

}  // namespace asval_test_common

#pragma once
// The fuzz input read as a stream of decisions. Past its end every read answers 0, so a short input still
// decodes to a complete (small) scenario, and every count it gives stops the loops that use it.
#include <cstddef>
#include <cstdint>

namespace asval::fuzz {

class ByteSource {
 public:
  ByteSource(const uint8_t* data, size_t size) : data_(data), left_(size) {}

  uint8_t U8() {
    if (left_ == 0) return 0;
    --left_;
    return *data_++;
  }
  // Low byte first; each read its own statement, so that every compiler decodes an input alike (the operands
  // of one expression are read in no fixed order).
  uint16_t U16() {
    const uint16_t low = U8();
    return static_cast<uint16_t>(low | (U8() << 8));
  }
  uint32_t U32() {
    const uint32_t low = U16();
    return low | (static_cast<uint32_t>(U16()) << 16);
  }
  uint64_t U64() {
    const uint64_t low = U32();
    return low | (static_cast<uint64_t>(U32()) << 32);
  }
  bool Bit() { return (U8() & 1) != 0; }
  // A value of enum type E that may be no enumerator: up to 0x7FFFFFFF, the headers' MAX_ENUM. (Past it, a C app
  // can pass the value, but loading it as the C++ enum is undefined behaviour in any C++ layer: UBSan says so.)
  template <typename E>
  E AnyEnum() {
    return static_cast<E>(U32() & 0x7fffffffu);
  }
  // A value in [0, n), n > 0; one byte when n fits in one.
  uint32_t Below(uint32_t n) { return n <= 256 ? U8() % n : U32() % n; }
  // True about once in n reads (never for an exhausted input).
  bool OneIn(uint32_t n) { return left_ != 0 && Below(n) == 0; }
  template <typename T, size_t N>
  T Pick(const T (&choices)[N]) {
    return choices[Below(static_cast<uint32_t>(N))];
  }
  bool empty() const { return left_ == 0; }

 private:
  const uint8_t* data_;
  size_t left_;
};

}  // namespace asval::fuzz

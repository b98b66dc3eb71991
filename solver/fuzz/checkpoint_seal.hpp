// A checkpoint's bytes with the header's payload size and the trailing checksum made to fit what
// lies between them (pipeline/formats.md §5). A mutation of the payload almost never keeps the
// FNV-1a checksum right, so without this the fuzzer would stop at the checksum check and never
// reach the field parser; pd_fuzz_checkpoint and the regression replay read both versions.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>

namespace pd_fuzz {

inline std::string sealed_checkpoint(std::string bytes) {
  constexpr std::size_t kSizeAt = 16, kHead = 24, kSum = 8;  // magic, version, byte-order mark; size
  if (bytes.size() < kHead + kSum) return bytes;
  const std::uint64_t size = bytes.size() - kHead - kSum;
  std::memcpy(&bytes[kSizeAt], &size, sizeof size);
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a-64, as io/checkpoint.cpp
  for (std::size_t k = kHead; k < kHead + size; ++k) {
    h ^= static_cast<unsigned char>(bytes[k]);
    h *= 1099511628211ull;
  }
  std::memcpy(&bytes[kHead + size], &h, sizeof h);
  return bytes;
}

}  // namespace pd_fuzz

// zlib blocks in the layout of VTK's vtkZLibDataCompressor (see vtk_zlib.hpp for the layout and
// where it is documented).
#include "io/vtk_zlib.hpp"

#include <zlib.h>

#include <cstring>

#include "core/error.hpp"

namespace pd {

namespace {

constexpr int kLevel = 1;  // see vtk_zlib.hpp: speed inside the time loop over a few per cent of size

void put_u64(unsigned char* at, std::uint64_t value) { std::memcpy(at, &value, 8); }  // little endian (vtu.cpp checks)

std::uint64_t get_u64(const unsigned char* at) {
  std::uint64_t value = 0;
  std::memcpy(&value, at, 8);
  return value;
}

}  // namespace

std::vector<unsigned char> vtk_zlib_compress(const unsigned char* data, std::size_t size, std::size_t block_size) {
  const std::size_t full = size / block_size, last = size % block_size;
  const std::size_t blocks = full + (last ? 1 : 0);
  std::vector<std::vector<unsigned char>> out(blocks);
  bool failed = false;
#pragma omp parallel for schedule(dynamic, 1) reduction(|| : failed)
  for (std::int64_t b = 0; b < static_cast<std::int64_t>(blocks); ++b) {
    const auto k = static_cast<std::size_t>(b);
    const std::size_t length = (k + 1 == blocks && last) ? last : block_size;
    uLongf bound = compressBound(static_cast<uLong>(length));
    out[k].resize(bound);
    failed = failed || compress2(out[k].data(), &bound, data + k * block_size, static_cast<uLong>(length), kLevel) != Z_OK;
    out[k].resize(bound);
  }
  if (failed) throw Error("zlib: compress2 failed (out of memory?)");
  // Header: n, B, the last block's size (0 when it is a full block, as VTK writes it), then the
  // compressed sizes.
  std::vector<unsigned char> bytes(8 * (3 + blocks));
  put_u64(&bytes[0], blocks);
  put_u64(&bytes[8], block_size);
  put_u64(&bytes[16], last);
  for (std::size_t k = 0; k < blocks; ++k) put_u64(&bytes[8 * (3 + k)], out[k].size());
  for (const auto& block : out) bytes.insert(bytes.end(), block.begin(), block.end());
  return bytes;
}

std::vector<unsigned char> vtk_zlib_decompress(const unsigned char* data, std::size_t available,
                                               std::size_t& consumed, const std::string& label) {
  auto fail = [&](const std::string& what) -> void { throw Error(label + ": compressed data: " + what); };
  if (available < 24) fail("the block header is truncated");
  const std::uint64_t blocks = get_u64(data), block_size = get_u64(data + 8), last = get_u64(data + 16);
  if (blocks > (available - 24) / 8) fail(std::to_string(blocks) + " blocks announced, more than the file holds");
  if (blocks > 0 && block_size == 0) fail("block size 0");
  if (last > block_size) fail("the last block (" + std::to_string(last) + " bytes) is larger than a block");
  const std::size_t header = 8 * (3 + static_cast<std::size_t>(blocks));
  std::size_t at = header;
  std::vector<unsigned char> out;
  for (std::uint64_t k = 0; k < blocks; ++k) {
    const std::uint64_t compressed = get_u64(data + 8 * (3 + k));
    if (compressed > available - at) fail("block " + std::to_string(k) + " runs past the data (truncated file?)");
    const std::uint64_t length = (k + 1 == blocks && last) ? last : block_size;
    // zlib's deflate never shrinks data by more than 1032:1: a larger claim is a forged header.
    if (length > 1032 * compressed + 64) fail("block " + std::to_string(k) + " claims an impossible ratio");
    const std::size_t start = out.size();
    out.resize(start + static_cast<std::size_t>(length));
    uLongf got = static_cast<uLongf>(length);
    const int rc = uncompress(out.data() + start, &got, data + at, static_cast<uLong>(compressed));
    if (rc != Z_OK || got != length)
      fail("block " + std::to_string(k) + " does not inflate to " + std::to_string(length) + " bytes (zlib: " +
           (rc == Z_OK ? "short" : zError(rc)) + ")");
    at += static_cast<std::size_t>(compressed);
  }
  consumed = at;
  return out;
}

}  // namespace pd

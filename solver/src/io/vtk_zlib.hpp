// The block layout that VTK's vtkZLibDataCompressor gives one DataArray of a compressed VTK XML
// file (VTK file-format documentation, "XML File Formats", binary and appended data; the
// itk.org wiki page "VTK XML Formats"): with header_type UInt64 every number below is a UInt64,
//
//   [number of blocks n] [uncompressed block size B] [uncompressed size of the last block, 0 if
//   it is a full B] [compressed size of block 1] … [compressed size of block n]
//   [block 1: zlib stream of B bytes] … [block n]
//
// so a reader can inflate block by block. Our own code, written from that description.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pd {

// VTK's writers cut arrays into blocks of 32 KiB (vtkXMLWriter's default BlockSize): the same here,
// so the block count is what ParaView itself would write.
constexpr std::size_t kVtkZlibBlockSize = 32768;

// Header and compressed blocks of `size` bytes at `data`, ready to be appended after a DataArray's
// offset. Blocks are compressed in parallel (OpenMP); each one alone, so the bytes do not depend on
// the thread count. zlib level 1: frames are written inside the time loop, and level 6 costs about
// three times the time for a few per cent less size on our arrays (measured in
// cases/plate_with_hole/README.md, "Output size").
std::vector<unsigned char> vtk_zlib_compress(const unsigned char* data, std::size_t size,
                                             std::size_t block_size = kVtkZlibBlockSize);

// The inverse: reads one compressed DataArray from `data` (at most `available` bytes), sets
// `consumed` to the bytes it used (header and blocks) and returns the uncompressed bytes. Throws
// pd::Error starting with `label` if the header or a block is inconsistent or does not inflate to
// the size the header announces. Memory is bounded by zlib's largest ratio (1032:1) times the
// compressed bytes, so a forged header cannot ask for more than the file could hold.
std::vector<unsigned char> vtk_zlib_decompress(const unsigned char* data, std::size_t available,
                                               std::size_t& consumed, const std::string& label);

}  // namespace pd

// The VTK XML UnstructuredGrid encoding of pipeline/formats.md §1 (appended raw data, UInt64
// headers, little endian, optionally zlib-compressed as VTK's vtkZLibDataCompressor writes it):
// one writer and one checking reader shared by node files and frames.
#pragma once
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace pd {

struct VtuArray {
  std::string name;
  std::string type;  // Float64 | Float32 | Int64 | Int32 | UInt8
  int components = 1;
  std::vector<unsigned char> bytes;  // raw little-endian values

  std::size_t value_size() const;
  std::size_t values() const { return bytes.size() / value_size(); }
  std::size_t tuples() const { return values() / static_cast<std::size_t>(components); }
};

template <class T>
const char* vtk_type_name();
template <> inline const char* vtk_type_name<double>() { return "Float64"; }
template <> inline const char* vtk_type_name<float>() { return "Float32"; }
template <> inline const char* vtk_type_name<std::int64_t>() { return "Int64"; }
template <> inline const char* vtk_type_name<std::int32_t>() { return "Int32"; }
template <> inline const char* vtk_type_name<std::uint8_t>() { return "UInt8"; }

template <class T>
VtuArray make_array(const std::string& name, const std::vector<T>& values, int components = 1) {
  VtuArray a{name, vtk_type_name<T>(), components, {}};
  const auto* first = reinterpret_cast<const unsigned char*>(values.data());
  a.bytes.assign(first, first + values.size() * sizeof(T));  // one copy, no zero fill before it
  return a;
}

// The values rounded to T (a frame's Float32 fields: the nearest float, as static_cast rounds).
template <class T>
VtuArray make_array_as(const std::string& name, const std::vector<double>& values) {
  if constexpr (std::is_same_v<T, double>) {
    return make_array(name, values);
  } else {
    std::vector<T> rounded(values.begin(), values.end());
    return make_array(name, rounded);
  }
}

// Interleaves three component arrays into one 3-component array of T (double or float).
template <class T = double>
VtuArray make_vec3_array(const std::string& name, const std::vector<double>& x, const std::vector<double>& y,
                         const std::vector<double>& z) {
  // Straight into the array's bytes: a frame has three of these.
  VtuArray a{name, vtk_type_name<T>(), 3, {}};
  a.bytes.resize(3 * x.size() * sizeof(T));
  auto* out = reinterpret_cast<T*>(a.bytes.data());
  for (std::size_t i = 0; i < x.size(); ++i) {
    out[3 * i] = static_cast<T>(x[i]);
    out[3 * i + 1] = static_cast<T>(y[i]);
    out[3 * i + 2] = static_cast<T>(z[i]);
  }
  return a;
}

// How write_vtu stores the arrays' bytes: raw, or in zlib blocks with the <VTKFile
// compressor="vtkZLibDataCompressor"> layout (io/vtk_zlib.hpp).
enum class VtuCompression { none, zlib };

struct VtuGrid {
  std::vector<VtuArray> field_data;  // FieldData (each NumberOfTuples = tuples())
  VtuArray points;                   // Float64 × 3
  std::vector<VtuArray> point_data;
  std::vector<VtuArray> cell_data;
  VtuArray connectivity, offsets, types;  // Int64, Int64, UInt8

  std::size_t points_count() const { return points.tuples(); }
  std::size_t cells_count() const { return types.values(); }

  const VtuArray* find(const std::vector<VtuArray>& section, const std::string& name) const {
    for (const auto& a : section)
      if (a.name == name) return &a;
    return nullptr;
  }
};

// Writes `path` through a temporary file renamed into place, so a reader never sees half a file.
void write_vtu(const std::filesystem::path& path, const VtuGrid& grid,
               VtuCompression compression = VtuCompression::none);

// Reads a file in exactly that encoding, raw or zlib-compressed; throws pd::Error naming the file
// and what is wrong (wrong header, another compressor, non-appended data, truncated data or
// blocks, sizes that do not match).
VtuGrid read_vtu(const std::filesystem::path& path);

// The same from the file's bytes (`file` only names it in messages); the fuzz targets call this.
VtuGrid parse_vtu(const std::string& text, const std::string& file);

// Typed copy of an array's values.
template <class T>
std::vector<T> values_of(const VtuArray& a) {
  std::vector<T> out(a.bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), a.bytes.data(), out.size() * sizeof(T));
  return out;
}

// A Float64 or Float32 array's values as doubles (a frame's fields are Float32 by default);
// throws pd::Error for another type.
std::vector<double> values_as_double(const VtuArray& a);

}  // namespace pd

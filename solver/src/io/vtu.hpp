// The VTK XML UnstructuredGrid encoding of pipeline/formats.md §1 (appended raw data, UInt64
// headers, little endian): one writer and one checking reader shared by node files and frames.
#pragma once
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace pd {

struct VtuArray {
  std::string name;
  std::string type;  // Float64 | Int64 | Int32 | UInt8
  int components = 1;
  std::vector<unsigned char> bytes;  // raw little-endian values

  std::size_t value_size() const;
  std::size_t values() const { return bytes.size() / value_size(); }
  std::size_t tuples() const { return values() / static_cast<std::size_t>(components); }
};

template <class T>
const char* vtk_type_name();
template <> inline const char* vtk_type_name<double>() { return "Float64"; }
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

// Interleaves three component arrays into one 3-component array.
VtuArray make_vec3_array(const std::string& name, const std::vector<double>& x, const std::vector<double>& y,
                         const std::vector<double>& z);

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
void write_vtu(const std::filesystem::path& path, const VtuGrid& grid);

// Reads a file in exactly that encoding; throws pd::Error naming the file and what is wrong
// (wrong header, compressed or non-appended data, truncated data, sizes that do not match).
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

}  // namespace pd

// Writer and checking reader for the VTK XML encoding of pipeline/formats.md §1, raw or with
// vtkZLibDataCompressor blocks (io/vtk_zlib.hpp).
#include "io/vtu.hpp"

#include "io/read_file.hpp"

#include <cctype>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/vtk_zlib.hpp"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the VTU reader and writer copy raw little-endian bytes; port them for a big-endian host"
#endif

namespace pd {

std::size_t VtuArray::value_size() const {
  if (type == "Float64" || type == "Int64" || type == "UInt64") return 8;
  if (type == "Int32" || type == "Float32" || type == "UInt32") return 4;
  if (type == "UInt8" || type == "Int8") return 1;
  if (type == "Int16" || type == "UInt16") return 2;
  return 1;
}

std::vector<double> values_as_double(const VtuArray& a) {
  if (a.type == "Float64") return values_of<double>(a);
  if (a.type == "Float32") {
    const std::vector<float> f = values_of<float>(a);
    return std::vector<double>(f.begin(), f.end());
  }
  throw Error("DataArray '" + a.name + "' is " + a.type + ", not Float64 or Float32");
}

// ---------------------------------------------------------------- writing

void write_vtu(const std::filesystem::path& path, const VtuGrid& g, VtuCompression compression) {
  const bool zlib = compression == VtuCompression::zlib;
  // Every array in the order of its data in the appended block: known before the XML head, since
  // each DataArray's offset (from the first byte after '_', VTK format doc, "Appended Data
  // Section") counts the bytes of the arrays before it, and compressed sizes are known only after
  // compressing.
  std::vector<const VtuArray*> order;
  for (const auto& a : g.field_data) order.push_back(&a);
  order.push_back(&g.points);
  for (const auto& a : g.point_data) order.push_back(&a);
  for (const auto& a : g.cell_data) order.push_back(&a);
  for (const VtuArray* a : {&g.connectivity, &g.offsets, &g.types}) order.push_back(a);
  std::vector<std::vector<unsigned char>> packed(zlib ? order.size() : 0);
  for (std::size_t k = 0; k < packed.size(); ++k)
    packed[k] = vtk_zlib_compress(order[k]->bytes.data(), order[k]->bytes.size());
  // Raw: a UInt64 byte count, then the bytes. zlib: the block header and blocks (vtk_zlib.hpp).
  auto stored_size = [&](std::size_t k) { return zlib ? packed[k].size() : 8 + order[k]->bytes.size(); };

  std::ostringstream head;
  std::size_t next = 0;
  std::uint64_t offset = 0;
  auto array_tag = [&](const VtuArray& a, bool field) {
    head << "        <DataArray type=\"" << a.type << "\" Name=\"" << a.name << "\" NumberOfComponents=\""
         << a.components << "\"";
    if (field) head << " NumberOfTuples=\"" << a.tuples() << "\"";
    head << " format=\"appended\" offset=\"" << offset << "\"/>\n";
    offset += stored_size(next++);
  };
  head << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\""
       << (zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") << ">\n"
       << "  <UnstructuredGrid>\n";
  if (!g.field_data.empty()) {
    head << "    <FieldData>\n";
    for (const auto& a : g.field_data) array_tag(a, true);
    head << "    </FieldData>\n";
  }
  head << "    <Piece NumberOfPoints=\"" << g.points_count() << "\" NumberOfCells=\"" << g.cells_count() << "\">\n";
  head << "      <Points>\n";
  array_tag(g.points, false);
  head << "      </Points>\n      <PointData>\n";
  for (const auto& a : g.point_data) array_tag(a, false);
  head << "      </PointData>\n      <CellData>\n";
  for (const auto& a : g.cell_data) array_tag(a, false);
  head << "      </CellData>\n      <Cells>\n";
  array_tag(g.connectivity, false);
  array_tag(g.offsets, false);
  array_tag(g.types, false);
  head << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n_";
  const std::string text = head.str();
  std::vector<std::uint64_t> counts;  // each array's byte count, the header of its appended block
  for (const VtuArray* a : order) counts.push_back(a->bytes.size());
  std::vector<std::string_view> pieces{text};
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (zlib) {
      pieces.emplace_back(reinterpret_cast<const char*>(packed[k].data()), packed[k].size());
      continue;
    }
    pieces.emplace_back(reinterpret_cast<const char*>(&counts[k]), 8);
    pieces.emplace_back(reinterpret_cast<const char*>(order[k]->bytes.data()), order[k]->bytes.size());
  }
  pieces.emplace_back("\n  </AppendedData>\n</VTKFile>\n");
  write_file_atomically(path, pieces);
}

// ---------------------------------------------------------------- reading

namespace {

struct Tag {
  std::string name;
  std::map<std::string, std::string> attributes;
  bool closing = false;       // </name>
  bool self_closing = false;  // <name ... />
};

class TagScanner {
 public:
  TagScanner(const std::string& text, std::size_t end, std::string file)
      : text_(text), end_(end), file_(std::move(file)) {}

  // Next element tag; false at the end. Skips <?xml ...?> and comments.
  bool next(Tag& tag) {
    for (;;) {
      const std::size_t open = text_.find('<', pos_);
      if (open == std::string::npos || open >= end_) return false;
      if (text_.compare(open, 4, "<!--") == 0) {
        const std::size_t close = text_.find("-->", open);
        if (close == std::string::npos || close >= end_) fail("unterminated XML comment");
        pos_ = close + 3;
        continue;
      }
      const std::size_t close = text_.find('>', open);
      if (close == std::string::npos || close >= end_) fail("unterminated XML tag");
      pos_ = close + 1;
      if (text_[open + 1] == '?' || text_[open + 1] == '!') continue;
      parse(text_.substr(open + 1, close - open - 1), tag);
      return true;
    }
  }

  [[noreturn]] void fail(const std::string& what) const { throw Error(file_ + ": " + what); }

 private:
  void parse(std::string body, Tag& tag) {
    tag = Tag{};
    if (!body.empty() && body[0] == '/') {
      tag.closing = true;
      body.erase(0, 1);
    }
    if (!body.empty() && body.back() == '/') {
      tag.self_closing = true;
      body.pop_back();
    }
    std::size_t p = 0;
    auto skip_space = [&] { while (p < body.size() && std::isspace(static_cast<unsigned char>(body[p]))) ++p; };
    skip_space();
    const std::size_t name_start = p;
    while (p < body.size() && !std::isspace(static_cast<unsigned char>(body[p]))) ++p;
    tag.name = body.substr(name_start, p - name_start);
    for (;;) {
      skip_space();
      if (p >= body.size()) break;
      const std::size_t key_start = p;
      while (p < body.size() && body[p] != '=' && !std::isspace(static_cast<unsigned char>(body[p]))) ++p;
      const std::string key = body.substr(key_start, p - key_start);
      skip_space();
      if (p >= body.size() || body[p] != '=') fail("malformed attribute '" + key + "' in <" + tag.name + ">");
      ++p;
      skip_space();
      if (p >= body.size() || (body[p] != '"' && body[p] != '\''))
        fail("attribute '" + key + "' in <" + tag.name + "> has no quoted value");
      const char quote = body[p++];
      const std::size_t value_end = body.find(quote, p);
      if (value_end == std::string::npos) fail("unterminated value of '" + key + "' in <" + tag.name + ">");
      tag.attributes[key] = body.substr(p, value_end - p);
      p = value_end + 1;
    }
  }

  const std::string& text_;
  std::size_t end_;
  std::string file_;
  std::size_t pos_ = 0;
};

std::uint64_t parse_count(const TagScanner& scan, const Tag& tag, const std::string& key) {
  auto it = tag.attributes.find(key);
  if (it == tag.attributes.end()) scan.fail("<" + tag.name + "> has no " + key + " attribute");
  const std::string& s = it->second;
  if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos)
    scan.fail("<" + tag.name + "> " + key + "=\"" + s + "\" is not a non-negative integer");
  // Digit by digit with a bound: std::stoull would throw std::out_of_range past 2^64 (found by fuzzing).
  constexpr std::uint64_t kLimit = std::uint64_t{1} << 62;
  std::uint64_t value = 0;
  for (const char digit : s) {
    value = 10 * value + static_cast<std::uint64_t>(digit - '0');
    if (value > kLimit) scan.fail("<" + tag.name + "> " + key + "=\"" + s.substr(0, 40) + "\" is too large");
  }
  return value;
}

struct PendingArray {
  std::string section;  // FieldData | Points | PointData | CellData | Cells
  VtuArray array;
  std::uint64_t offset = 0;
  std::uint64_t tuples = 0;  // FieldData: NumberOfTuples; else 0 (decided by the piece)
};

}  // namespace

VtuGrid read_vtu(const std::filesystem::path& path) {
  const std::string file = path.string();
  return parse_vtu(read_whole_file(path, "the VTK file"), file);
}

VtuGrid parse_vtu(const std::string& text, const std::string& file) {
  if (text.empty()) throw Error(file + ": the file is empty");

  const std::size_t appended = text.find("<AppendedData");
  TagScanner scan(text, appended == std::string::npos ? text.size() : appended, file);
  Tag tag;
  if (!scan.next(tag) || tag.name != "VTKFile")
    scan.fail("not a VTK XML file (the first element is not <VTKFile>)");
  auto expect = [&](const std::string& key, const std::string& want) {
    auto it = tag.attributes.find(key);
    const std::string got = it == tag.attributes.end() ? "(missing)" : it->second;
    if (got != want) scan.fail("<VTKFile> " + key + " is " + got + ", expected " + want + " (pipeline/formats.md §1)");
  };
  expect("type", "UnstructuredGrid");
  expect("byte_order", "LittleEndian");
  expect("header_type", "UInt64");
  bool zlib = false;
  if (tag.attributes.count("compressor") && !tag.attributes.at("compressor").empty()) {
    if (tag.attributes.at("compressor") != "vtkZLibDataCompressor")
      scan.fail("compressed data (compressor=\"" + tag.attributes.at("compressor") + "\") is not supported; "
                "write raw or vtkZLibDataCompressor appended data (pipeline/formats.md §1)");
    zlib = true;
  }

  std::vector<std::string> stack{"VTKFile"};
  std::vector<PendingArray> arrays;
  int pieces = 0;
  std::uint64_t n_points = 0, n_cells = 0;
  while (scan.next(tag)) {
    if (tag.closing) {
      if (stack.empty() || stack.back() != tag.name) scan.fail("unexpected </" + tag.name + ">");
      stack.pop_back();
      continue;
    }
    // An element after </VTKFile> has no parent: stack.back() below would read before the vector
    // (found by fuzzing; invisible to ASan because libstdc++'s string copy is not instrumented).
    if (stack.empty()) scan.fail("<" + tag.name + "> after </VTKFile>");
    if (tag.name == "Piece") {
      if (++pieces > 1) scan.fail("more than one <Piece>; the format has exactly one");
      n_points = parse_count(scan, tag, "NumberOfPoints");
      n_cells = parse_count(scan, tag, "NumberOfCells");
    } else if (tag.name == "DataArray") {
      PendingArray p;
      p.section = stack.back();
      if (p.section != "FieldData" && p.section != "Points" && p.section != "PointData" &&
          p.section != "CellData" && p.section != "Cells")
        scan.fail("<DataArray> inside <" + p.section + ">");
      const auto& at = tag.attributes;
      p.array.name = at.count("Name") ? at.at("Name") : "";
      const std::string label = "DataArray '" + p.array.name + "' in <" + p.section + ">";
      p.array.type = at.count("type") ? at.at("type") : "";
      if (p.array.type != "Float64" && p.array.type != "Float32" && p.array.type != "Int64" &&
          p.array.type != "Int32" && p.array.type != "UInt8")
        scan.fail(label + " has type '" + p.array.type + "'; expected Float64, Float32, Int64, Int32 or UInt8");
      const std::string format = at.count("format") ? at.at("format") : "(missing)";
      if (format != "appended")
        scan.fail(label + " has format=\"" + format + "\"; every array must be format=\"appended\" (pipeline/formats.md §1)");
      const std::uint64_t components = at.count("NumberOfComponents") ? parse_count(scan, tag, "NumberOfComponents") : 1;
      // Bounded before the cast to int; VTK's own arrays have at most 9 components (a tensor).
      if (components < 1 || components > 1024) scan.fail(label + " has NumberOfComponents outside 1..1024");
      p.array.components = static_cast<int>(components);
      p.offset = parse_count(scan, tag, "offset");
      if (p.section == "FieldData") p.tuples = parse_count(scan, tag, "NumberOfTuples");
      arrays.push_back(std::move(p));
    }
    if (!tag.self_closing) stack.push_back(tag.name);
  }
  if (appended == std::string::npos)
    scan.fail("no <AppendedData> block: the file is truncated or not in the appended-raw encoding");
  if (pieces != 1) scan.fail("no <Piece> element");

  // <AppendedData encoding="raw">, whitespace, '_', then the data.
  const std::size_t tag_end = text.find('>', appended);
  if (tag_end == std::string::npos) scan.fail("truncated <AppendedData> tag");
  if (text.substr(appended, tag_end - appended).find("encoding=\"raw\"") == std::string::npos)
    scan.fail("<AppendedData> must have encoding=\"raw\" (base64 is not supported)");
  std::size_t underscore = tag_end + 1;
  while (underscore < text.size() && std::isspace(static_cast<unsigned char>(text[underscore]))) ++underscore;
  if (underscore >= text.size() || text[underscore] != '_')
    scan.fail("the appended data does not start with '_'");
  const std::size_t data_begin = underscore + 1;
  const std::size_t data_end = text.rfind("</AppendedData>");
  if (data_end == std::string::npos || data_end < data_begin)
    scan.fail("no </AppendedData>: the file is truncated");

  VtuGrid g;
  bool have_points = false;
  for (auto& p : arrays) {
    const std::string label = "DataArray '" + p.array.name + "' in <" + p.section + ">";
    const std::size_t value_size = p.array.value_size();
    if (p.offset > data_end - data_begin || data_end - data_begin - p.offset < 8)
      scan.fail(label + ": offset " + std::to_string(p.offset) + " lies beyond the data (truncated file?)");
    std::vector<unsigned char> inflated;
    std::uint64_t count = 0;
    std::size_t start = data_begin + p.offset + 8;
    if (zlib) {
      std::size_t consumed = 0;
      inflated = vtk_zlib_decompress(reinterpret_cast<const unsigned char*>(text.data()) + data_begin + p.offset,
                                     data_end - data_begin - p.offset, consumed, file + ": " + label);
      count = inflated.size();
    } else {
      std::memcpy(&count, text.data() + data_begin + p.offset, 8);
      if (count > data_end - start)
        scan.fail(label + ": " + std::to_string(count) + " bytes announced but only " +
                  std::to_string(data_end - start) + " left (truncated file?)");
    }
    if (count % (value_size * static_cast<std::size_t>(p.array.components)) != 0)
      scan.fail(label + ": " + std::to_string(count) + " bytes is not a whole number of tuples");
    const std::uint64_t tuples = count / (value_size * static_cast<std::size_t>(p.array.components));
    std::uint64_t want = tuples;
    if (p.section == "FieldData") want = p.tuples;
    else if (p.section == "Points" || p.section == "PointData") want = n_points;
    else if (p.section == "CellData" || (p.section == "Cells" && p.array.name != "connectivity")) want = n_cells;
    if (tuples != want)
      scan.fail(label + " has " + std::to_string(tuples) + " tuples, expected " + std::to_string(want));
    if (zlib)
      p.array.bytes = std::move(inflated);
    else
      p.array.bytes.assign(text.begin() + static_cast<std::ptrdiff_t>(start),
                           text.begin() + static_cast<std::ptrdiff_t>(start + count));
    if (p.section == "FieldData") g.field_data.push_back(std::move(p.array));
    else if (p.section == "PointData") g.point_data.push_back(std::move(p.array));
    else if (p.section == "CellData") g.cell_data.push_back(std::move(p.array));
    else if (p.section == "Points") {
      if (have_points) scan.fail("more than one array in <Points>");
      if (p.array.type != "Float64" || p.array.components != 3) scan.fail("<Points> must be Float64 with 3 components");
      g.points = std::move(p.array);
      have_points = true;
    } else if (p.array.name == "connectivity") g.connectivity = std::move(p.array);
    else if (p.array.name == "offsets") g.offsets = std::move(p.array);
    else if (p.array.name == "types") g.types = std::move(p.array);
    else scan.fail("unexpected " + label);
  }
  if (!have_points) scan.fail("no <Points> array");
  if (g.connectivity.type != "Int64" || g.offsets.type != "Int64" || g.types.type != "UInt8")
    scan.fail("<Cells> needs connectivity (Int64), offsets (Int64) and types (UInt8)");
  const auto conn = values_of<std::int64_t>(g.connectivity);
  const auto offs = values_of<std::int64_t>(g.offsets);
  std::int64_t previous = 0;
  for (std::size_t c = 0; c < offs.size(); ++c) {
    if (offs[c] < previous) scan.fail("cell offsets decrease at cell " + std::to_string(c));
    previous = offs[c];
  }
  if (static_cast<std::size_t>(previous) != conn.size())
    scan.fail("the last cell offset (" + std::to_string(previous) + ") differs from the connectivity length (" +
              std::to_string(conn.size()) + ")");
  for (std::size_t k = 0; k < conn.size(); ++k)
    if (conn[k] < 0 || static_cast<std::uint64_t>(conn[k]) >= n_points)
      scan.fail("cell connectivity entry " + std::to_string(k) + " = " + std::to_string(conn[k]) +
                " is not a point index");
  return g;
}

}  // namespace pd

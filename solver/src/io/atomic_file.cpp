// Whole-or-absent files: written under a temporary name beside the target, then renamed into place.
#include "io/atomic_file.hpp"

#include <fstream>

#include "core/error.hpp"

namespace pd {

void write_file_atomically(const std::filesystem::path& path, const std::vector<std::string_view>& pieces) {
  const std::filesystem::path tmp = path.string() + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(tmp.string() + ": cannot open for writing");
    // Piece by piece from where the data lie: a frame's arrays are not first copied into one string.
    for (const std::string_view piece : pieces) out.write(piece.data(), static_cast<std::streamsize>(piece.size()));
    out.close();
    if (!out) throw Error(tmp.string() + ": write failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw Error(path.string() + ": cannot rename " + tmp.string() + " into place: " + ec.message());
}

void write_file_atomically(const std::filesystem::path& path, const std::string& text) {
  write_file_atomically(path, std::vector<std::string_view>{text});
}

}  // namespace pd

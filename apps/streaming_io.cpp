/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "streaming_io.h"

#include "cloud_io.h"
#include <sys/types.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

namespace cocone_app {

namespace {

constexpr bool HOST_LITTLE_ENDIAN = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

/** Bytes read or written at a time: large enough that the system calls cost nothing
 * next to the conversion, small enough to stay in the cache. */
constexpr std::size_t BLOCK_BYTES = std::size_t(1) << 20;

/** A header line or token list longer than this is not a header. */
constexpr std::size_t MAX_HEADER_LINE = 65536;
constexpr int MAX_HEADER_LINES = 10000;

/** Where a point's x, y, z lie in the records of a binary file. */
struct Layout {
  /** Byte offset of the first record, bytes per record, points. */
  std::uint64_t data_start = 0;
  std::size_t record = 0, points = 0;
  /** Offset of x, y, z in the record and whether each is a double (else a float). */
  std::array<std::size_t, 3> offset{{0, 0, 0}};
  std::array<bool, 3> is_double{{false, false, false}};
  /** The file's byte order is not the host's. */
  bool swap = false;
};

/** One value of a record, in the host's byte order. */
template <bool Swap>
inline double
value(const char* p, bool is_double)
{
  if (is_double) {
    std::uint64_t bits;
    std::memcpy(&bits, p, 8);
    if (Swap)
      bits = __builtin_bswap64(bits);
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  std::uint32_t bits;
  std::memcpy(&bits, p, 4);
  if (Swap)
    bits = __builtin_bswap32(bits);
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}

template <bool Swap>
void
decode(const char* records, std::size_t n, const Layout& l, Eigen::Vector3d* out)
{
  for (std::size_t i = 0; i < n; ++i, records += l.record)
    for (int k = 0; k < 3; ++k)
      out[i][k] = value<Swap>(records + l.offset[k], l.is_double[k]);
}

/** A binary file's records read block by block, x, y, z picked out of each. */
class BinaryPointStream : public pcl::cocone::PointSource {
public:
  BinaryPointStream(std::string path, std::FILE* file, const Layout& layout)
  : path_(std::move(path))
  , file_(file)
  , layout_(layout)
  , buffer_(std::max<std::size_t>(1, BLOCK_BYTES / layout.record) * layout.record)
  , unread_(layout.points)
  {}

  ~BinaryPointStream() override { std::fclose(file_); }

  BinaryPointStream(const BinaryPointStream&) = delete;
  BinaryPointStream&
  operator=(const BinaryPointStream&) = delete;

  bool
  rewind(std::string& error) override
  {
    std::clearerr(file_);
    if (::fseeko(file_, static_cast<off_t>(layout_.data_start), SEEK_SET) != 0) {
      error = "cannot read '" + path_ + "': " + std::strerror(errno);
      return false;
    }
    begin_ = end_ = 0;
    unread_ = layout_.points;
    return true;
  }

  bool
  read(std::vector<Eigen::Vector3d>& chunk,
       std::size_t max,
       std::string& error) override
  {
    chunk.clear();
    const std::size_t record = layout_.record;
    const std::size_t left = unread_ + (end_ - begin_) / record;
    if (max == 0 && left > 0) {
      error = "cannot read '" + path_ + "': a chunk of 0 points asked for";
      return false;
    }
    chunk.reserve(std::min(max, left));
    while (chunk.size() < max && (begin_ < end_ || unread_ > 0)) {
      if (begin_ == end_) {
        const std::size_t n = std::min(unread_, buffer_.size() / record);
        if (std::fread(buffer_.data(), record, n, file_) != n) {
          // The size was checked at open: the file changed since, or the disk failed.
          error = "cannot read '" + path_ + "': " +
                  (std::ferror(file_) ? std::strerror(errno)
                                      : "the file is shorter than when opened");
          chunk.clear();
          return false;
        }
        unread_ -= n;
        begin_ = 0;
        end_ = n * record;
      }
      const std::size_t take = std::min(max - chunk.size(), (end_ - begin_) / record);
      const std::size_t first = chunk.size();
      chunk.resize(first + take);
      if (layout_.swap)
        decode<true>(buffer_.data() + begin_, take, layout_, chunk.data() + first);
      else
        decode<false>(buffer_.data() + begin_, take, layout_, chunk.data() + first);
      begin_ += take * record;
    }
    return true;
  }

private:
  std::string path_;
  std::FILE* file_;
  Layout layout_;
  std::vector<char> buffer_;
  /** The bytes of the buffer not yet returned, and the points not yet buffered. */
  std::size_t begin_ = 0, end_ = 0, unread_ = 0;
};

/** The next header line without its end ("\n" or "\r\n"), split into words. False at
 * the end of the file or on a line too long for a header. */
bool
headerLine(std::FILE* file, std::vector<std::string>& words)
{
  std::string line;
  for (int c; (c = std::fgetc(file)) != '\n';) {
    if (c == EOF || line.size() >= MAX_HEADER_LINE)
      return false;
    line.push_back(static_cast<char>(c));
  }
  words.clear();
  std::istringstream tokens(line);
  for (std::string word; tokens >> word;)
    words.push_back(word);
  return true;
}

/** Bytes of a PLY scalar type; 0 if it is not one. */
std::size_t
plyTypeSize(const std::string& type)
{
  static const std::pair<const char*, std::size_t> TYPES[] = {{"char", 1},
                                                              {"uchar", 1},
                                                              {"int8", 1},
                                                              {"uint8", 1},
                                                              {"short", 2},
                                                              {"ushort", 2},
                                                              {"int16", 2},
                                                              {"uint16", 2},
                                                              {"int", 4},
                                                              {"uint", 4},
                                                              {"int32", 4},
                                                              {"uint32", 4},
                                                              {"float", 4},
                                                              {"float32", 4},
                                                              {"double", 8},
                                                              {"float64", 8}};
  for (const auto& t : TYPES)
    if (type == t.first)
      return t.second;
  return 0;
}

/** Whether \a n records of \a record bytes fit in \a bytes (without overflow). */
bool
fits(std::uint64_t n, std::size_t record, std::uint64_t bytes)
{
  return n <= bytes / record;
}

/** Read a binary PLY header: the vertex element's layout. Elements before it are
 * skipped by size, so they must have fixed-size records (no list). */
bool
readPlyHeader(std::FILE* file, std::uint64_t file_size, Layout& l, std::string& why)
{
  struct Element {
    std::string name;
    std::size_t count = 0, record = 0;
    bool list = false;
  };
  std::vector<Element> elements;
  std::size_t vertex = SIZE_MAX; // the first element named "vertex"
  std::vector<std::string> w;
  std::array<bool, 3> have{{false, false, false}};
  bool format = false;
  why = "not a valid .ply header";
  if (!headerLine(file, w) || w.size() != 1 || w[0] != "ply")
    return false;
  for (int lines = 0;; ++lines) {
    if (lines == MAX_HEADER_LINES || !headerLine(file, w))
      return false;
    if (w.empty())
      continue;
    const std::string& key = w[0];
    if (key == "end_header")
      break;
    if (key == "format") {
      if (w.size() != 3)
        return false;
      if (w[1] == "ascii") {
        why = "ascii";
        return false;
      }
      if (w[1] != "binary_little_endian" && w[1] != "binary_big_endian") {
        why = "unknown PLY format '" + w[1] + "'";
        return false;
      }
      l.swap = (w[1] == "binary_little_endian") != HOST_LITTLE_ENDIAN;
      format = true;
    }
    else if (key == "element") {
      elements.emplace_back();
      if (w.size() != 3 || !parseCount(w[2], elements.back().count)) {
        why = "element '" + (w.size() > 1 ? w[1] : "") + "' has no valid count";
        return false;
      }
      elements.back().name = w[1];
      if (w[1] == "vertex" && vertex == SIZE_MAX)
        vertex = elements.size() - 1;
    }
    else if (key == "property") {
      if (elements.empty())
        return false;
      Element& e = elements.back();
      if (w.size() == 5 && w[1] == "list") {
        if (!plyTypeSize(w[2]) || !plyTypeSize(w[3]))
          return false;
        e.list = true;
        continue;
      }
      const std::size_t size = w.size() == 3 ? plyTypeSize(w[1]) : 0;
      if (size == 0)
        return false;
      const char* const XYZ = "xyz";
      if (elements.size() - 1 == vertex && w[2].size() == 1 &&
          std::strchr(XYZ, w[2][0])) {
        const int k = static_cast<int>(std::strchr(XYZ, w[2][0]) - XYZ);
        if (have[k]) {
          why = "the vertex element has two '" + w[2] + "' properties";
          return false;
        }
        if (w[1] != "float" && w[1] != "float32" && w[1] != "double" &&
            w[1] != "float64") {
          why = "vertex property '" + w[2] + "' is of type " + w[1] +
                " (streaming needs float or double)";
          return false;
        }
        have[k] = true;
        l.offset[k] = e.record;
        l.is_double[k] = size == 8;
      }
      e.record += size;
    }
    else if (key != "comment" && key != "obj_info")
      return false;
  }
  if (!format)
    return false;
  if (vertex == SIZE_MAX) {
    why = "no vertex element";
    return false;
  }
  const off_t data = ::ftello(file);
  if (data < 0)
    return false;
  // Skip the elements before the vertex element by their sizes.
  l.data_start = static_cast<std::uint64_t>(data);
  for (std::size_t i = 0; i <= vertex; ++i) {
    const Element& e = elements[i];
    if (i == vertex) {
      if (e.list) {
        why = "the vertex element has a list property (records of varying size)";
        return false;
      }
      for (int k = 0; k < 3; ++k)
        if (!have[k]) {
          why = std::string("the vertex element has no '") + "xyz"[k] + "' property";
          return false;
        }
      l.points = e.count;
      l.record = e.record;
      return true;
    }
    if (e.list) {
      why = "element '" + e.name +
            "' comes before the vertex element and has a list property (its size "
            "is not known without reading it)";
      return false;
    }
    if (e.record > 0 && !fits(e.count, e.record, file_size - l.data_start))
      break;
    l.data_start += std::uint64_t(e.count) * e.record;
  }
  why = "truncated: the file is shorter than the elements its header declares";
  return false;
}

/** Read a PCD header (DATA binary): x, y, z's layout. */
bool
readPcdHeader(std::FILE* file, Layout& l, std::string& why)
{
  const std::set<std::string>& keys = pcdHeaderKeys();
  std::vector<std::string> fields, sizes, types, counts, w;
  std::size_t width = 0, height = 1, points = 0;
  bool have_width = false, have_points = false;
  std::set<std::string> seen;
  why = "not a valid .pcd header";
  for (int lines = 0;; ++lines) {
    if (lines == MAX_HEADER_LINES || !headerLine(file, w))
      return false;
    if (w.empty() || w[0][0] == '#')
      continue;
    const std::string key = w[0];
    if (!keys.count(key) || !seen.insert(key).second)
      return false;
    w.erase(w.begin());
    if (key == "FIELDS" || key == "COLUMNS")
      fields = w;
    else if (key == "SIZE")
      sizes = w;
    else if (key == "TYPE")
      types = w;
    else if (key == "COUNT")
      counts = w;
    else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      std::size_t& count = key == "WIDTH" ? width : key == "HEIGHT" ? height : points;
      if (w.size() != 1 || !parseCount(w[0], count)) {
        why = key + " is not a count";
        return false;
      }
      have_width |= key == "WIDTH";
      have_points |= key == "POINTS";
    }
    else if (key == "DATA") {
      if (w.size() != 1)
        return false;
      if (w[0] == "ascii" || w[0] == "binary_compressed") {
        why = w[0];
        return false;
      }
      if (w[0] != "binary") {
        why = "unknown DATA '" + w[0] + "'";
        return false;
      }
      break;
    }
  }
  if (fields.empty() || sizes.size() != fields.size() ||
      types.size() != fields.size() ||
      (!counts.empty() && counts.size() != fields.size()) || !have_width)
    return false;
  std::array<bool, 3> have{{false, false, false}};
  for (std::size_t i = 0; i < fields.size(); ++i) {
    std::size_t size = 0, count = 1;
    if (!parseCount(sizes[i], size) ||
        (size != 1 && size != 2 && size != 4 && size != 8) ||
        (types[i] != "I" && types[i] != "U" && types[i] != "F") ||
        (!counts.empty() &&
         (!parseCount(counts[i], count) || count == 0 || count > 65536)))
      return false;
    const auto k = fields[i].size() == 1 ? std::string("xyz").find(fields[i][0])
                                         : std::string::npos;
    if (k != std::string::npos) {
      if (have[k]) {
        why = "two '" + fields[i] + "' fields";
        return false;
      }
      if (types[i] != "F" || size < 4 || count != 1) {
        why = "field '" + fields[i] + "' is not TYPE F, SIZE 4 or 8, COUNT 1";
        return false;
      }
      have[k] = true;
      l.offset[k] = l.record;
      l.is_double[k] = size == 8;
    }
    l.record += size * count;
  }
  for (int k = 0; k < 3; ++k)
    if (!have[k]) {
      why = std::string("no '") + "xyz"[k] + "' field";
      return false;
    }
  if (height != 0 && width > std::numeric_limits<std::size_t>::max() / height) {
    why = "WIDTH * HEIGHT overflows";
    return false;
  }
  l.points = width * height;
  if (have_points && points != l.points) {
    why = "POINTS is not WIDTH * HEIGHT";
    return false;
  }
  const off_t data = ::ftello(file);
  if (data < 0)
    return false;
  l.data_start = static_cast<std::uint64_t>(data);
  return true;
}

} // namespace

std::unique_ptr<pcl::cocone::PointSource>
openPointStream(const std::string& path, std::size_t& points, std::string& error)
{
  points = 0;
  const std::string ext = extension(path);
  if (ext != "ply" && ext != "pcd") {
    error =
        "cannot stream '" + path + "': only binary .ply and .pcd files can be streamed";
    return nullptr;
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) {
    error = "cannot read '" + path + "': " + std::strerror(errno);
    return nullptr;
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> owner(file, &std::fclose);
  if (::fseeko(file, 0, SEEK_END) != 0) {
    error = "cannot read '" + path + "': " + std::strerror(errno);
    return nullptr;
  }
  const off_t end = ::ftello(file);
  std::rewind(file);
  if (end <= 0) {
    error = "cannot read '" + path + "': " + (end < 0 ? std::strerror(errno) : "empty");
    return nullptr;
  }
  const auto file_size = static_cast<std::uint64_t>(end);
  Layout l;
  std::string why;
  if (!(ext == "ply" ? readPlyHeader(file, file_size, l, why)
                     : readPcdHeader(file, l, why))) {
    if (why == "ascii")
      error = "'" + path + "' is ASCII: streaming needs " +
              (ext == "ply" ? "binary" : "uncompressed binary (DATA binary)");
    else if (why == "binary_compressed")
      error = "'" + path +
              "' is compressed (DATA binary_compressed): streaming needs uncompressed "
              "binary";
    else
      error = "cannot stream '" + path + "': " + why;
    return nullptr;
  }
  // As checkPcdHeader(): a longer record is not a point cloud's.
  if (l.record > 65536) {
    error = "cannot stream '" + path + "': records of more than 65536 bytes";
    return nullptr;
  }
  if (l.points == 0) {
    error = "cannot stream '" + path + "': no points";
    return nullptr;
  }
  if (l.data_start > file_size || !fits(l.points, l.record, file_size - l.data_start)) {
    error = "cannot stream '" + path + "': truncated: the header declares " +
            std::to_string(l.points) + " points of " + std::to_string(l.record) +
            " bytes, the file has room for " +
            std::to_string(
                l.data_start > file_size ? 0 : (file_size - l.data_start) / l.record);
    return nullptr;
  }
  auto stream = std::make_unique<BinaryPointStream>(path, owner.release(), l);
  if (!stream->rewind(error))
    return nullptr;
  points = l.points;
  return stream;
}

PlyMeshWriter::PlyMeshWriter(std::string path) : path_(std::move(path)) {}

PlyMeshWriter::~PlyMeshWriter()
{
  if (file_)
    std::fclose(file_);
  if (!ended_ && !temporary_.empty())
    std::remove(temporary_.c_str());
}

bool
PlyMeshWriter::fail(const std::string& why, std::string& error)
{
  if (file_)
    std::fclose(file_);
  file_ = nullptr;
  if (!ended_ && !temporary_.empty())
    std::remove(temporary_.c_str());
  failed_ = true;
  error = "cannot write '" + path_ + "': " + why;
  return false;
}

bool
PlyMeshWriter::flush()
{
  const std::size_t n = used_;
  used_ = 0;
  return std::fwrite(buffer_.data(), 1, n, file_) == n;
}

bool
PlyMeshWriter::put(const void* bytes, std::size_t size)
{
  if (used_ + size > buffer_.size()) {
    if (!flush())
      return false;
    if (size > buffer_.size())
      buffer_.resize(size);
  }
  std::memcpy(buffer_.data() + used_, bytes, size);
  used_ += size;
  return true;
}

bool
PlyMeshWriter::begin(std::size_t vertices, std::size_t triangles, std::string& error)
{
  if (begun_)
    return fail("begin() called twice", error);
  begun_ = true;
  // The faces' indices are PLY ints.
  if (vertices > std::size_t(INT_MAX))
    return fail("more vertices than a PLY int index can number", error);
  vertices_ = vertices;
  triangles_ = triangles;
  temporary_ = temporaryName(path_);
  file_ = std::fopen(temporary_.c_str(), "wb");
  if (!file_) {
    const std::string why = std::strerror(errno);
    temporary_.clear(); // not created: nothing to remove
    return fail(why, error);
  }
  buffer_.resize(BLOCK_BYTES);
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment pcl_cocone_reconstruction\n"
         << "element vertex " << vertices << "\nproperty float x\nproperty float y\n"
         << "property float z\nproperty float nx\nproperty float ny\n"
         << "property float nz\nelement face " << triangles
         << "\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string text = header.str();
  if (!put(text.data(), text.size()))
    return fail(std::strerror(errno), error);
  return true;
}

bool
PlyMeshWriter::addVertices(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<Eigen::Vector3d>& normals,
                           const std::vector<int>& /*ids*/,
                           std::string& error)
{
  if (failed_)
    return fail("an earlier call failed", error);
  if (!begun_ || ended_)
    return fail("addVertices() outside begin() ... end()", error);
  if (positions.size() != normals.size())
    return fail("not one normal per vertex", error);
  if (triangles_written_ > 0)
    return fail("vertices after triangles", error);
  if (positions.size() > vertices_ - vertices_written_)
    return fail("more vertices than the " + std::to_string(vertices_) + " announced",
                error);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    std::uint32_t record[6];
    for (int k = 0; k < 6; ++k) {
      const float v = static_cast<float>(k < 3 ? positions[i][k] : normals[i][k - 3]);
      std::memcpy(&record[k], &v, 4);
      if (!HOST_LITTLE_ENDIAN)
        record[k] = __builtin_bswap32(record[k]);
    }
    if (!put(record, sizeof(record)))
      return fail(std::strerror(errno), error);
  }
  vertices_written_ += positions.size();
  return true;
}

bool
PlyMeshWriter::addTriangles(const std::vector<pcl::cocone::Triangle>& triangles,
                            std::string& error)
{
  if (failed_)
    return fail("an earlier call failed", error);
  if (!begun_ || ended_)
    return fail("addTriangles() outside begin() ... end()", error);
  if (vertices_written_ != vertices_)
    return fail("triangles before all the vertices", error);
  if (triangles.size() > triangles_ - triangles_written_)
    return fail("more triangles than the " + std::to_string(triangles_) + " announced",
                error);
  for (const auto& t : triangles) {
    char record[13];
    record[0] = 3;
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || std::size_t(t[k]) >= vertices_)
        return fail("triangle index " + std::to_string(t[k]) + " is not a vertex",
                    error);
      std::uint32_t v = static_cast<std::uint32_t>(t[k]);
      if (!HOST_LITTLE_ENDIAN)
        v = __builtin_bswap32(v);
      std::memcpy(record + 1 + 4 * k, &v, 4);
    }
    if (!put(record, sizeof(record)))
      return fail(std::strerror(errno), error);
  }
  triangles_written_ += triangles.size();
  return true;
}

bool
PlyMeshWriter::end(std::string& error)
{
  if (failed_)
    return fail("an earlier call failed", error);
  if (!begun_ || ended_)
    return fail("end() without begin(), or twice", error);
  if (vertices_written_ != vertices_ || triangles_written_ != triangles_)
    return fail("wrote " + std::to_string(vertices_written_) + " of the " +
                    std::to_string(vertices_) + " vertices and " +
                    std::to_string(triangles_written_) + " of the " +
                    std::to_string(triangles_) + " triangles announced",
                error);
  if (!flush())
    return fail(std::strerror(errno), error);
  // A full disk may only show when the last block is written out, at close.
  const int closed = std::fclose(file_);
  file_ = nullptr;
  if (closed != 0)
    return fail(std::strerror(errno), error);
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0)
    return fail(std::strerror(errno), error);
  ended_ = true;
  return true;
}

} // namespace cocone_app

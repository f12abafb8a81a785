// The tags of a v5 sparse variable checked against the array that holds them (internal/mat_v5_check.hpp).
//
// v5 layout (MathWorks, "MAT-File Format"): a 128-byte header whose last two bytes tell the byte order, then data
// elements, each an 8-byte tag (type, byte count) and its data padded to 8 bytes; a tag whose upper 16 bits are
// not zero is a small element (count in the upper half, 4 data bytes inline). A variable is a miMATRIX element
// (type 14), stored as is or inside a zlib stream (miCOMPRESSED, type 15); a sparse one holds array flags, dims,
// name, then ir, jc and the real (and imaginary) values.
#include "internal/mat_v5_check.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>

namespace dynid::internal {

namespace {

constexpr std::uint32_t kMiMatrix = 14, kMiCompressed = 15;
constexpr std::uint32_t kSparseClass = 5, kComplexFlag = 0x0800;

// Bytes in file order, from the file itself or from a variable's inflated zlib stream.
class Source {
 public:
  virtual ~Source() = default;
  virtual bool read(void* dst, std::uint64_t n) = 0;
  virtual bool skip(std::uint64_t n) = 0;
};

class FileSource : public Source {
 public:
  explicit FileSource(std::ifstream& in) : in_(in) {}
  bool read(void* dst, std::uint64_t n) override {
    return static_cast<bool>(in_.read(static_cast<char*>(dst), static_cast<std::streamsize>(n)));
  }
  bool skip(std::uint64_t n) override {
    return static_cast<bool>(in_.seekg(static_cast<std::streamoff>(n), std::ios::cur));
  }

 private:
  std::ifstream& in_;
};

// Inflates `compressed` bytes of the file as they are asked for.
class ZlibSource : public Source {
 public:
  ZlibSource(std::ifstream& in, std::uint64_t compressed) : in_(in), left_(compressed) {
    std::memset(&z_, 0, sizeof z_);
    ok_ = inflateInit(&z_) == Z_OK;
  }
  ~ZlibSource() override {
    if (ok_) inflateEnd(&z_);
  }
  bool read(void* dst, std::uint64_t n) override { return pull(static_cast<unsigned char*>(dst), n); }
  bool skip(std::uint64_t n) override { return pull(nullptr, n); }

 private:
  bool pull(unsigned char* dst, std::uint64_t n) {
    std::array<unsigned char, 1 << 14> scratch;
    while (n > 0) {
      if (!ok_ || ended_) return false;
      if (z_.avail_in == 0) {
        if (left_ == 0) return false;
        const std::uint64_t take = std::min<std::uint64_t>(left_, in_buf_.size());
        if (!in_.read(reinterpret_cast<char*>(in_buf_.data()), static_cast<std::streamsize>(take))) return false;
        left_ -= take;
        z_.next_in = in_buf_.data();
        z_.avail_in = static_cast<uInt>(take);
      }
      const std::uint64_t want = std::min<std::uint64_t>(n, scratch.size());
      z_.next_out = dst ? dst : scratch.data();
      z_.avail_out = static_cast<uInt>(want);
      const int rc = inflate(&z_, Z_NO_FLUSH);
      if (rc != Z_OK && rc != Z_STREAM_END) return false;
      const std::uint64_t got = want - z_.avail_out;
      n -= got;
      if (dst) dst += got;
      if (rc == Z_STREAM_END) ended_ = true;
    }
    return true;
  }
  std::ifstream& in_;
  std::uint64_t left_;
  z_stream z_;
  bool ok_ = false, ended_ = false;
  std::array<unsigned char, 1 << 14> in_buf_{};
};

struct Tag {
  std::uint32_t type = 0;
  std::uint64_t bytes = 0;   // data bytes declared
  std::uint64_t stored = 0;  // bytes the element takes after its first 8 (data and padding; 0 for a small one)
  bool small = false;
  std::array<unsigned char, 4> inline_data{};
};

std::uint32_t u32(const unsigned char* p, bool swap) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return swap ? __builtin_bswap32(v) : v;
}

bool read_tag(Source& s, bool swap, Tag* t) {
  unsigned char b[8];
  if (!s.read(b, 8)) return false;
  const std::uint32_t first = u32(b, swap);
  if (first >> 16) {
    t->small = true;
    t->type = first & 0xFFFF;
    t->bytes = first >> 16;
    t->stored = 0;
    std::memcpy(t->inline_data.data(), b + 4, 4);
  } else {
    t->small = false;
    t->type = first;
    t->bytes = u32(b + 4, swap);
    t->stored = (t->bytes + 7) / 8 * 8;
  }
  return true;
}

// Checks one miMATRIX element of `size` bytes (its tag read): "" unless it is the sparse variable `name` with a
// sub-element declaring more than the array holds. *found is set when the variable is `name`.
std::string check_matrix(Source& s, bool swap, std::uint64_t size, const std::string& name, bool* found) {
  std::uint64_t left = size;
  auto next = [&](Tag* t) {
    if (left < 8 || !read_tag(s, swap, t)) return false;
    left -= 8;
    return true;
  };
  Tag flags, dims, nm;
  if (!next(&flags) || flags.small || flags.bytes < 8 || flags.stored > left) return "";
  unsigned char fb[8];
  if (!s.read(fb, 8) || !s.skip(flags.stored - 8)) return "";
  left -= flags.stored;
  const std::uint32_t word = u32(fb, swap);
  if (!next(&dims) || dims.stored > left || !s.skip(dims.stored)) return "";
  left -= dims.stored;
  if (!next(&nm) || nm.stored > left) return "";
  std::string var;
  if (nm.small) {
    var.assign(reinterpret_cast<const char*>(nm.inline_data.data()), std::min<std::uint64_t>(nm.bytes, 4));
  } else {
    if (nm.bytes > 4096) return "";
    var.resize(nm.bytes);
    if (!s.read(var.data(), nm.bytes) || !s.skip(nm.stored - nm.bytes)) return "";
    left -= nm.stored;
  }
  if (var != name) return "";
  *found = true;
  if ((word & 0xFF) != kSparseClass) return "";
  const char* what[] = {"row indices (ir)", "column pointers (jc)", "values", "imaginary values"};
  const int parts = (word & kComplexFlag) ? 4 : 3;
  for (int k = 0; k < parts; ++k) {
    Tag t;
    if (!next(&t)) return "";
    if (!t.small && t.bytes > left)
      return std::string("its sparse ") + what[k] + " declare " + std::to_string(t.bytes) +
             " bytes where the array holds " + std::to_string(left);
    if (k + 1 == parts) break;
    if (!s.skip(t.stored)) return "";
    left -= t.stored;
  }
  return "";
}

}  // namespace

std::string v5_sparse_damage(const std::string& path, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[128];
  if (!in.read(reinterpret_cast<char*>(header), 128)) return "";
  bool swap;
  if (header[126] == 'I' && header[127] == 'M')
    swap = false;
  else if (header[126] == 'M' && header[127] == 'I')
    swap = true;
  else
    return "";  // not v5 (v4 or v7.3/HDF5): libmatio's own checks apply
  in.seekg(0, std::ios::end);
  const std::uint64_t file_size = static_cast<std::uint64_t>(in.tellg());
  std::uint64_t pos = 128;
  FileSource file(in);
  while (pos + 8 <= file_size) {
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    Tag t;
    if (!read_tag(file, swap, &t) || t.small) return "";
    const std::uint64_t body = file_size - pos - 8;
    bool found = false;
    std::string why;
    if (t.type == kMiMatrix) {
      why = check_matrix(file, swap, std::min(t.bytes, body), name, &found);
    } else if (t.type == kMiCompressed) {
      // The inflated array cannot exceed zlib's largest ratio (about 1032:1) times the compressed bytes.
      const std::uint64_t packed = std::min(t.bytes, body);
      ZlibSource z(in, packed);
      Tag inner;
      if (read_tag(z, swap, &inner) && !inner.small && inner.type == kMiMatrix)
        why = check_matrix(z, swap, std::min<std::uint64_t>(inner.bytes, 1100 * packed + 1000000), name, &found);
    }
    if (!why.empty() || found) return why;
    pos += 8 + (t.type == kMiCompressed ? t.bytes : t.stored);
  }
  return "";
}

}  // namespace dynid::internal

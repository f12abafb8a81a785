// Every v5 variable's tags checked against the array that holds them (internal/mat_v5_check.hpp).
//
// v5 layout (MathWorks, "MAT-File Format"): a 128-byte header whose last two bytes tell the byte order, then data
// elements, each an 8-byte tag (type, byte count) and its data padded to 8 bytes; a tag whose upper 16 bits are
// not zero is a small element (count in the upper half, 4 data bytes inline). A variable is a miMATRIX element
// (type 14), stored as is or inside a zlib stream (miCOMPRESSED, type 15). An array holds its flags, dims and
// name, then by class: the real (and imaginary) data of a numeric or char array; ir, jc and the values of a
// sparse one; one miMATRIX element per cell of a cell array; the field name length, the field names and one
// miMATRIX element per field of a struct (an object first names its class).
#include "internal/mat_v5_check.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "internal/mat_reader.hpp"

namespace dynid::internal {

namespace {

constexpr std::uint32_t kMiInt8 = 1, kMiInt32 = 5, kMiUint32 = 6, kMiMatrix = 14, kMiCompressed = 15;
constexpr std::uint32_t kComplexFlag = 0x0800;
// Array classes (the low byte of the flags).
constexpr std::uint32_t kCell = 1, kStruct = 2, kObject = 3, kChar = 4, kSparse = 5, kDouble = 6, kUint64 = 15,
                        kFunction = 16;
constexpr int kMaxDepth = 64;

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
      const std::uint64_t got = want - z_.avail_out;
      n -= got;
      if (dst) dst += got;
      // The bytes inflated before an error count, as libmatio uses them (fuzz_mat, 2026-11-28: a stream whose
      // checksum fails right after a cell array's dimensions; the walk lost them and libmatio allocated 1.65e9 cells).
      if (rc == Z_STREAM_END || (rc != Z_OK && got > 0))
        ended_ = true;
      else if (rc != Z_OK)
        return false;
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

bool read_tag(Source& s, bool swap, Tag* t) {
  unsigned char b[8];
  if (!s.read(b, 8)) return false;
  const std::uint32_t first = load_u32(b, swap);
  if (first >> 16) {
    t->small = true;
    t->type = first & 0xFFFF;
    t->bytes = first >> 16;
    t->stored = 0;
    std::memcpy(t->inline_data.data(), b + 4, 4);
  } else {
    t->small = false;
    t->type = first;
    t->bytes = load_u32(b + 4, swap);
    t->stored = (t->bytes + 7) / 8 * 8;
  }
  return true;
}

// The walk of one array element: what is wrong with it ("" when every tag it reached fits). `end` is set when
// the bytes ran out or the layout is one this walk does not know: the rest is left to libmatio's own checks.
class ArrayWalk {
 public:
  ArrayWalk(Source& s, bool swap) : s_(s), swap_(swap) {}
  // Whether the last refusal was of something dynid does not read rather than of damage.
  bool refused_unsupported() const { return unsupported_; }
  // The miMATRIX element `who` of `size` bytes, its tag read; consumes all of them unless the walk ended. A
  // top-level array (depth 0) is named by its variable name once that is read.
  std::string array(std::uint64_t size, std::string who, int depth) {
    if (depth > kMaxDepth) {
      unsupported();
      return who + " is nested more than " + std::to_string(kMaxDepth) + " levels deep (dynid reads at most that)";
    }
    // Flags (16 bytes), dimensions (16 at least) and a name (8 at least): a smaller array element is damage that
    // libmatio reads past, into whatever follows (fuzz_mat, 2026-11-28: a top-level array of 0 bytes, then
    // dimensions declaring 4 GB). A nested array of 0 bytes is an empty cell or field.
    if (size < 40 && (depth == 0 || size > 0))
      return who + ": its array element declares " + std::to_string(size) +
             " bytes, fewer than the 40 its flags, dimensions and name take";
    std::uint64_t left = size;
    Tag flags, dims, name;
    if (!next(&left, &flags)) return cut(who);
    // Array flags are two 32-bit words (miUINT32, or miINT32 as some writers store them) in a full tag in every
    // MAT-file writer's output; anything else is damage that libmatio would read on into dimensions of any size
    // (fuzz_mat, 2026-11-28: a small-element flags tag). libmatio reads 8 bytes of flags whatever their tag
    // declares, so a tag declaring more would put this walk and libmatio at different places (fuzz_mat: flags
    // declaring 63 bytes; libmatio read the next words as dimensions and a cell array, and allocated 3.8 GB).
    if (flags.small || flags.bytes != 8 || (flags.type != kMiUint32 && flags.type != kMiInt32))
      return who + ": its array flags are not the two 32-bit words a MAT-file holds";
    if (over(flags, left)) return who + declares("array flags", flags, left);
    unsigned char fb[8];
    if (!s_.read(fb, 8) || !pass(&left, flags, 8)) return cut(who);
    const std::uint32_t word = load_u32(fb, swap_);
    if (!next(&left, &dims)) return cut(who);
    if (over(dims, left)) return who + declares("dimensions", dims, left);
    // From here on the walk must read what libmatio reads: it takes dims.bytes / 4 dimensions and a name only from
    // an miINT8 tag (reading on from the name's data otherwise), so other layouts are refused, not skipped.
    if (!dims.small && (dims.type != kMiInt32 || dims.bytes % 4 != 0))
      return who + ": its dimensions are not 32-bit integers (type " + std::to_string(dims.type) + ", " +
             std::to_string(dims.bytes) + " bytes)";
    Count n;
    if (!read_dims(&left, dims, &n)) return cut(who);
    const std::uint32_t cls = word & 0xFF;
    // libmatio sizes a cell array by its dimensions even when what follows them is unreadable: checked before the
    // name (a name tag of 8 bytes at least comes first).
    if (cls == kCell && left >= 8)
      if (std::string why = room(who, n, n.elements, "cells", left - 8); !why.empty()) return why;
    if (!next(&left, &name)) return cut(who);
    if (over(name, left)) return who + declares("name", name, left);
    if (!name.small && name.type != kMiInt8)
      return who + ": its name is not text (type " + std::to_string(name.type) + ")";
    std::string var;
    if (name.small) {
      var.assign(reinterpret_cast<const char*>(name.inline_data.data()), std::min<std::uint64_t>(name.bytes, 4));
    } else {
      var.resize(std::min<std::uint64_t>(name.bytes, 256));
      if (!s_.read(var.data(), var.size()) || !pass(&left, name, var.size())) return cut(who);
    }
    if (depth == 0) who = "variable '" + var + "'";
    const bool complex = word & kComplexFlag;
    std::string why;
    if (cls == kCell)
      why = cells(&left, who, depth, n);
    else if (cls == kStruct || cls == kObject)
      why = fields(&left, who, depth, cls == kObject, n);
    else if (cls == kSparse)
      why = parts(&left, who, complex ? 4 : 3, nullptr);
    else if (cls == kChar || (cls >= kDouble && cls <= kUint64))
      why = parts(&left, who, complex ? 2 : 1, &n);
    else if (cls == kFunction) {
      // libmatio 1.5.23 reads a function handle's elements as the variables that follow it, and on a damaged one
      // frees them with free(), leaking their contents (fuzz_mat, 2026-11-28); dynid reads no function handles.
      unsupported();
      why = who + " is a MATLAB function handle (array class 16), which dynid does not read";
    }
    // else: opaque objects, which dynid does not read; libmatio checks them.
    if (!why.empty() || end_ || depth == 0) return why;  // a top-level array need not be read to its end
    if (!s_.skip(left)) return stop();
    return "";
  }

 private:
  // An array's element count (its dimensions' product) and its dimensions as text ("1 x 100000000").
  struct Count {
    long double elements = 1;  // elements, cells or struct elements
    std::string shape;
  };
  // Reads the dimensions `dims` declares (fitting in the array: checked) into their product and text.
  bool read_dims(std::uint64_t* left, const Tag& dims, Count* n) {
    const auto add = [&](const unsigned char* p) {
      const std::uint32_t d = load_u32(p, swap_);
      n->elements *= d;
      n->shape += (n->shape.empty() ? "" : " x ") + std::to_string(d);
    };
    if (dims.small) {
      for (std::uint64_t k = 0; k + 4 <= dims.bytes; k += 4) add(dims.inline_data.data() + k);
      return true;
    }
    unsigned char d[4];
    for (std::uint64_t k = 0; k + 4 <= dims.bytes; k += 4) {
      if (!s_.read(d, 4)) return false;
      add(d);
    }
    return pass(left, dims, dims.bytes / 4 * 4);
  }
  // The fewest bytes per value of a data element of MAT-file type `type` (miINT8 = 1 ... miUINT64 = 13; for
  // miUTF8/16/32 = 16..18 per UTF-16 unit of a char array: one UTF-8 byte at least, and a surrogate pair is one
  // 4-byte UTF-32 value); 0 for a type that sizes nothing.
  static std::uint64_t value_bytes(std::uint32_t type) {
    static const std::uint64_t size[] = {0, 1, 1, 2, 2, 4, 4, 4, 0, 8, 0, 0, 8, 8, 0, 0, 1, 2, 2};
    return type < std::size(size) ? size[type] : 0;
  }
  static std::string count_text(long double n) {
    return n < 1e19L ? std::to_string(static_cast<std::uint64_t>(n)) : "more than 10^19";
  }
  // A tag declaring more data than the array holds, or a small element declaring more than the 4 bytes its tag
  // holds (libmatio reads such a count on as the element's size: fuzz_mat, 2026-11-28, a rank of 905,969,664).
  static bool over(const Tag& t, std::uint64_t left) { return t.small ? t.bytes > 4 : t.bytes > left; }
  bool next(std::uint64_t* left, Tag* t) {
    if (*left < 8 || !read_tag(s_, swap_, t)) return false;
    *left -= 8;
    return true;
  }
  // Past the data of `t` (and its padding, as far as the array holds it), `done` of its bytes already read.
  bool pass(std::uint64_t* left, const Tag& t, std::uint64_t done) {
    const std::uint64_t n = std::min(t.stored, *left);
    if (n < done || !s_.skip(n - done)) return false;
    *left -= n;
    return true;
  }
  std::string stop() {
    end_ = true;
    return "";
  }
  static std::string declares(const std::string& what, const Tag& t, std::uint64_t holds) {
    return ": its " + what + " declare " + std::to_string(t.bytes) + " bytes where " +
           (t.small ? std::string("a small data element holds at most 4") : "the array holds " + std::to_string(holds));
  }
  // `n` data elements in a row (a numeric or char array's real and imaginary data; a sparse array's ir, jc and
  // values): each must fit, and a numeric or char array's data (`values`: its count; null for a sparse array) must
  // hold that many values: libmatio sizes the array by its dimensions, not by its data. The last element's data is
  // left to the caller (a top-level array is not read further).
  std::string parts(std::uint64_t* left, const std::string& who, int n, const Count* values) {
    const bool sparse = values == nullptr;
    static const char* const numeric_names[] = {"real data", "imaginary data"};
    static const char* const sparse_names[] = {"sparse row indices (ir)", "sparse column pointers (jc)",
                                               "sparse values", "sparse imaginary values"};
    for (int k = 0; k < n; ++k) {
      Tag t;
      if (!next(left, &t)) return stop();
      const char* what = sparse ? sparse_names[k] : numeric_names[k];
      if (over(t, *left)) return who + declares(what, t, *left);
      if (!sparse && values->elements * static_cast<long double>(value_bytes(t.type)) > t.bytes)
        return who + ": its dimensions " + values->shape + " declare " + count_text(values->elements) +
               " values where its " + what + " hold " + std::to_string(t.bytes) + " bytes";
      if (k + 1 < n && !pass(left, t, 0)) return stop();
    }
    return "";
  }
  std::string nested(std::uint64_t* left, const std::string& who, int depth) {
    Tag t;
    if (!next(left, &t)) return stop();
    // libmatio takes any tag whose second word is 0 as an empty element and reads on (a walk that stopped there
    // would leave the next elements unchecked); any other tag that is not miMATRIX ends its reading.
    if ((t.small ? load_u32(t.inline_data.data(), swap_) : t.bytes) == 0) return "";
    if (t.small || t.type != kMiMatrix) return stop();
    if (over(t, *left))
      return who + ": its array element declares " + std::to_string(t.bytes) +
             " bytes where the enclosing array holds " + std::to_string(*left);
    const std::uint64_t n = std::min(t.stored, *left);
    const std::string why = array(n, who, depth + 1);
    if (!why.empty() || end_) return why;
    *left -= n;
    return "";
  }
  // libmatio allocates a cell array's or struct's elements (a pointer and a header each) by its dimensions before
  // reading any (fuzz_mat, CI 2026-11-28: a cell array declaring 10^8 cells, 2 GB and 11 s to free): each element is
  // a nested array element of 8 bytes at least, so `elements` of them must fit in what the array holds.
  static std::string room(const std::string& who, const Count& n, long double elements, const char* what,
                          std::uint64_t left) {
    if (elements * 8 <= static_cast<long double>(left)) return "";
    return who + ": its dimensions " + n.shape + " declare " + count_text(elements) + " " + what + " where the array " +
           "holds " + std::to_string(left) + " bytes, room for " + std::to_string(left / 8) + " at most";
  }
  std::string cells(std::uint64_t* left, const std::string& who, int depth, const Count& n) {
    if (std::string why = room(who, n, n.elements, "cells", *left); !why.empty()) return why;
    // libmatio reads as many cells as the dimensions declare, then goes on after the array: so does the walk (fuzz_mat,
    // 2026-11-28: an empty cell array followed by 8 bytes the walk read as a cell and stopped at, while libmatio went
    // on to the next cell and a 7 GB rank).
    for (std::uint64_t k = 0; k < n.elements; ++k) {
      if (*left < 8)
        return who + ": its dimensions " + n.shape + " declare " + count_text(n.elements) +
               " cells where the array holds " + std::to_string(k);
      const std::string why = nested(left, who + " cell " + std::to_string(k + 1), depth);
      if (!why.empty() || end_) return why;
    }
    return "";
  }
  std::string fields(std::uint64_t* left, const std::string& who, int depth, bool object, const Count& count) {
    Tag t;
    if (object) {
      if (!next(left, &t)) return stop();
      if (over(t, *left)) return who + declares("class name", t, *left);
      if (!pass(left, t, 0)) return stop();
    }
    if (!next(left, &t)) return stop();
    // libmatio reads the field name length as a tag and one word, whatever the tag declares, and stops at 0.
    if (!t.small || t.type != kMiInt32 || t.bytes != 4)
      return who + ": its field name length is not one 32-bit integer";
    const std::uint32_t length = load_u32(t.inline_data.data(), swap_);
    if (length == 0 || !next(left, &t)) return stop();
    if (over(t, *left)) return who + declares("field names", t, *left);
    // libmatio reads as many whole names as the tag holds and then its padding, not the tag's padded size.
    if (!t.small && (t.type != kMiInt8 || t.bytes % length != 0))
      return who + ": its field names (" + std::to_string(t.bytes) + " bytes) are not names of " +
             std::to_string(length) + " bytes";
    if (!pass(left, t, 0)) return stop();
    const std::uint64_t n = length ? t.bytes / length : 0;
    const long double elements = count.elements * static_cast<long double>(n);
    if (std::string why = room(who, count, elements, "fields (elements x fields)", *left); !why.empty()) return why;
    for (std::uint64_t k = 0; k < elements; ++k) {  // element-major, as MAT-files store them
      if (*left < 8)
        return who + ": its dimensions " + count.shape + " and " + std::to_string(n) + " fields declare " +
               count_text(elements) + " fields where the array holds " + std::to_string(k);
      const std::string where = count.elements == 1 ? who : who + " element " + std::to_string(k / n + 1);
      const std::string why = nested(left, where + " field " + std::to_string(k % n + 1), depth);
      if (!why.empty() || end_) return why;
    }
    return "";
  }

  void unsupported() { unsupported_ = true; }
  // An array whose bytes end inside its flags, dimensions or name: libmatio reads on from whatever its buffer holds
  // (fuzz_mat, 2026-11-28: a zlib stream cut after half a dimension, read by libmatio as 1650614786 cells).
  static std::string cut(const std::string& who) {
    return who +
           ": its data end inside its flags, dimensions and name (the file is cut short, or its compressed "
           "data are damaged)";
  }
  Source& s_;
  bool swap_;
  bool end_ = false;
  bool unsupported_ = false;
};

}  // namespace

std::string v5_damage(const std::string& path, bool* unsupported) {
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
    const std::string where = "the variable at byte " + std::to_string(pos);
    std::string why;
    bool refused_unsupported = false;
    const auto walk = [&](Source& source, std::uint64_t size) {
      ArrayWalk w(source, swap);
      why = w.array(size, where, 0);
      refused_unsupported = w.refused_unsupported();
    };
    if (t.type == kMiMatrix) {
      walk(file, std::min(t.bytes, body));
    } else if (t.type == kMiCompressed) {
      // The inflated array cannot exceed zlib's largest ratio (about 1032:1) times the compressed bytes.
      const std::uint64_t packed = std::min(t.bytes, body);
      ZlibSource z(in, packed);
      Tag inner;
      if (read_tag(z, swap, &inner) && !inner.small && inner.type == kMiMatrix)
        walk(z, std::min(inner.bytes, static_cast<std::uint64_t>(max_inflated_bytes(static_cast<double>(packed)))));
    }
    if (unsupported) *unsupported = refused_unsupported;
    if (!why.empty()) return why;
    // libmatio goes on 8 + the declared bytes after a variable, padded or not (fuzz_mat, 2026-11-28: a variable of
    // 1073 bytes; the walk went on at its padded end, libmatio 7 bytes earlier, into a function handle).
    pos += 8 + t.bytes;
  }
  return "";
}

}  // namespace dynid::internal

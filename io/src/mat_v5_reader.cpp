// dynid's MATLAB v5 reader (internal/mat_reader.hpp).
//
// v5 layout (MathWorks, "MAT-File Format"): a 128-byte header whose last two bytes tell the byte order, then data
// elements, each an 8-byte tag (type, byte count) and its data padded to 8 bytes; a tag whose upper 16 bits are not
// zero is a small element (count in the upper half, at most 4 data bytes inline). A variable is a miMATRIX element
// (type 14), stored as is or inside a zlib stream (miCOMPRESSED, type 15). An array holds its flags (class, complex
// and logical bits; a sparse array's nzmax), dims and name, then by class: the real (and imaginary) data of a numeric
// or char array; ir, jc and the values of a sparse one; one miMATRIX element per cell of a cell array.
//
// Every count this reader allocates by is bounded by the bytes an element holds: a dimension product is checked
// against the data before a vector is sized, a cell count against the bytes of its array (8 at least per cell), and a
// compressed variable is inflated as its stream yields bytes, never into a buffer of its declared size.
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>

#include "dynid/mesh/error.hpp"
#include "internal/mat_reader.hpp"

namespace dynid::internal {

bool MatArray::numeric() const {
  static const char* const kinds[] = {"double", "single", "int8",  "uint8",  "int16",  "uint16",
                                      "int32",  "uint32", "int64", "uint64", "logical"};
  return std::find(std::begin(kinds), std::end(kinds), type) != std::end(kinds);
}

namespace {

constexpr std::uint32_t kMiInt8 = 1, kMiInt32 = 5, kMiMatrix = 14, kMiCompressed = 15, kMiUtf8 = 16, kMiUtf16 = 17,
                        kMiUtf32 = 18;
constexpr std::uint32_t kLogicalFlag = 0x0200, kComplexFlag = 0x0800;
constexpr std::uint32_t kCell = 1, kStruct = 2, kObject = 3, kChar = 4, kSparse = 5, kDouble = 6, kUint64 = 15,
                        kFunction = 16, kOpaque = 17;
constexpr int kMaxDepth = 64;
// Bytes of a variable inflated to list it: its flags, dimensions (up to about 8,000) and name.
constexpr std::uint64_t kHeaderBytes = 1 << 15;

// What is wrong with an array, said of it ("variable 'c' cell 2: its real data declare ..."); MatV5Reader adds the
// file and the advice.
struct Damage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bytes [p, p + n) of one array, read front to back.
struct Span {
  const unsigned char* p;
  std::uint64_t n;
  void advance(std::uint64_t k) {
    p += k;
    n -= k;
  }
};

struct Element {
  std::uint32_t type = 0;
  const unsigned char* data = nullptr;
  std::uint64_t bytes = 0;
};

// The next data element of `s` (`what` names it in messages), `s` moved past it and its padding as far as `s` holds.
Element next(Span* s, bool swap, const std::string& who, const std::string& what) {
  if (s->n < 8)
    throw Damage(who + ": its " + what + " are missing (its array ends " + std::to_string(s->n) + " bytes on)");
  const std::uint32_t first = load_u32(s->p, swap);
  Element e;
  if (first >> 16) {  // small element: count in the upper half, data in the tag's second word
    e.type = first & 0xFFFF;
    e.bytes = first >> 16;
    if (e.bytes > 4)
      throw Damage(who + ": its " + what + " declare " + std::to_string(e.bytes) +
                   " bytes where a small data element holds at most 4");
    e.data = s->p + 4;
    s->advance(8);
    return e;
  }
  e.type = first;
  e.bytes = load_u32(s->p + 4, swap);
  if (e.bytes > s->n - 8)
    throw Damage(who + ": its " + what + " declare " + std::to_string(e.bytes) + " bytes where the array holds " +
                 std::to_string(s->n - 8));
  e.data = s->p + 8;
  s->advance(8 + std::min((e.bytes + 7) / 8 * 8, s->n - 8));
  return e;
}

// Bytes per value of MAT-file data type `type` (miINT8 = 1 ... miUINT64 = 13); 0 for a type that holds no numbers.
std::uint64_t value_size(std::uint32_t type) {
  static const std::uint64_t size[] = {0, 1, 1, 2, 2, 4, 4, 4, 0, 8, 0, 0, 8, 8};
  return type < std::size(size) ? size[type] : 0;
}

// Value k of numeric data of MAT-file type `type`, as a double.
double value(const unsigned char* data, std::uint32_t type, std::uint64_t k, bool swap) {
  const unsigned char* p = data + k * value_size(type);
  switch (type) {
    case 1:
      return load_as_double<std::int8_t>(p, swap);
    case 2:
      return load_as_double<std::uint8_t>(p, swap);
    case 3:
      return load_as_double<std::int16_t>(p, swap);
    case 4:
      return load_as_double<std::uint16_t>(p, swap);
    case 5:
      return load_as_double<std::int32_t>(p, swap);
    case 6:
      return load_as_double<std::uint32_t>(p, swap);
    case 7:
      return load_as_double<float>(p, swap);
    case 9:
      return load_as_double<double>(p, swap);
    case 12:
      return load_as_double<std::int64_t>(p, swap);
    default:
      return load_as_double<std::uint64_t>(p, swap);  // 13
  }
}

// The values of numeric element `e`: `count` of them (all it holds when count < 0), checked to be there.
std::vector<double> values_of(const Element& e, long double count, bool swap, const std::string& who,
                              const std::string& what, const std::string& shape) {
  const std::uint64_t size = value_size(e.type);
  if (size == 0)
    throw Damage(who + ": its " + what + " are of MAT-file data type " + std::to_string(e.type) + ", not numbers");
  const std::uint64_t held = e.bytes / size;
  if (count >= 0 && count > static_cast<long double>(held))
    throw Damage(who + ": its dimensions " + shape + " declare " +
                 (count < 1e19L ? std::to_string(static_cast<std::uint64_t>(count)) : std::string("more than 10^19")) +
                 " values where its " + what + " hold " + std::to_string(e.bytes) + " bytes");
  std::vector<double> v(count >= 0 ? static_cast<std::uint64_t>(count) : held);
  for (std::uint64_t k = 0; k < v.size(); ++k) v[k] = value(e.data, e.type, k, swap);
  return v;
}

// Non-negative integers below 2^32 (a sparse array's ir and jc).
std::vector<std::uint32_t> indices_of(const Element& e, bool swap, const std::string& who, const std::string& what) {
  const std::vector<double> v = values_of(e, -1, swap, who, what, "");
  std::vector<std::uint32_t> out(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!(v[k] >= 0 && v[k] < 4294967296.0) || v[k] != static_cast<double>(static_cast<std::uint32_t>(v[k])))
      throw Damage(who + ": its " + what + " hold " + std::to_string(v[k]) + " at entry " + std::to_string(k + 1) +
                   ", not an index");
    out[k] = static_cast<std::uint32_t>(v[k]);
  }
  return out;
}

long double element_count(const MatArray& a) {
  long double n = 1;
  for (std::size_t d : a.dims) n *= static_cast<long double>(d);
  return n;
}

std::string shape_of(const MatArray& a) { return dims_text(a.dims); }

// A char array's text as UTF-16 code units (MATLAB's char), `count` of them: 16-bit values are units; miUTF8 is
// decoded, and 32-bit values are code points; 8-bit values are Latin-1. Writers count a text's characters in code
// points (SciPy) or in UTF-16 units (MATLAB): when the code points are `count`, each is one unit (U+FFFD above U+FFFF),
// else a code point above U+FFFF is two units. Throws when fewer than `count` units are there.
std::vector<std::uint32_t> text_of(const Element& e, bool swap, const std::string& who, const MatArray& a,
                                   long double count) {
  std::vector<std::uint32_t> codes;
  if (e.type == kMiUtf8) {
    for (std::uint64_t k = 0; k < e.bytes;) {
      const unsigned char c = e.data[k];
      const int more = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
      if (more < 0 || k + static_cast<std::uint64_t>(more) >= e.bytes) {
        codes.push_back(0xFFFD);
        ++k;
        continue;
      }
      std::uint32_t code = more == 0 ? c : c & (0x3F >> more);
      for (int j = 1; j <= more; ++j) code = code << 6 | (e.data[k + static_cast<std::uint64_t>(j)] & 0x3F);
      codes.push_back(code);
      k += 1 + static_cast<std::uint64_t>(more);
    }
  } else {
    const std::uint64_t size = e.type == kMiUtf16 ? 2 : e.type == kMiUtf32 ? 4 : value_size(e.type);
    if (size == 0 || size == 8 || e.type == 7)
      throw Damage(who + ": its text is of MAT-file data type " + std::to_string(e.type) + ", not characters");
    for (std::uint64_t k = 0; k + size <= e.bytes; k += size) {
      std::uint32_t c = e.data[k];
      if (size == 2) {
        std::uint16_t h;
        std::memcpy(&h, e.data + k, 2);
        c = swap ? __builtin_bswap16(h) : h;
      } else if (size == 4) {
        c = load_u32(e.data + k, swap);
      }
      codes.push_back(c);
    }
  }
  std::vector<std::uint32_t> units;
  const bool one_each = static_cast<long double>(codes.size()) == count;
  for (std::uint32_t c : codes) {
    if (c > 0xFFFF && !one_each && c <= 0x10FFFF) {
      units.push_back(0xD800 + ((c - 0x10000) >> 10));
      units.push_back(0xDC00 + ((c - 0x10000) & 0x3FF));
    } else {
      units.push_back(c > 0xFFFF ? 0xFFFD : c);
    }
  }
  if (static_cast<long double>(units.size()) < count)
    throw Damage(who + ": its dimensions " + shape_of(a) + " declare " +
                 std::to_string(static_cast<std::uint64_t>(count)) + " characters where its text holds " +
                 std::to_string(units.size()));
  units.resize(static_cast<std::size_t>(count));
  return units;
}

const char* class_name(std::uint32_t cls, bool logical) {
  static const char* const names[] = {"",       "cell",   "struct", "object", "char",     "sparse",
                                      "double", "single", "int8",   "uint8",  "int16",    "uint16",
                                      "int32",  "uint32", "int64",  "uint64", "function", "opaque"};
  if (logical && cls >= kDouble && cls <= kUint64) return "logical";
  return cls < std::size(names) ? names[cls] : "";
}

// An array's flags, dimensions and name (the `header` fields of MatArray), `s` moved past them; `cls` its class.
MatArray header(Span* s, bool swap, std::string who, std::uint32_t* cls, bool* logical) {
  MatArray a;
  const Element flags = next(s, swap, who, "array flags");
  if (flags.bytes != 8) throw Damage(who + ": its array flags are not the two 32-bit words a MAT-file holds");
  const std::uint32_t word = load_u32(flags.data, swap);
  *cls = word & 0xFF;
  *logical = word & kLogicalFlag;
  a.complex = word & kComplexFlag;
  if (class_name(*cls, false)[0] == '\0')
    throw Damage(who + ": its array class " + std::to_string(*cls) + " is not one MATLAB writes");
  a.type = class_name(*cls, *logical);
  const Element dims = next(s, swap, who, "dimensions");
  if (dims.type != kMiInt32 || dims.bytes % 4 != 0)
    throw Damage(who + ": its dimensions are not 32-bit integers (type " + std::to_string(dims.type) + ", " +
                 std::to_string(dims.bytes) + " bytes)");
  for (std::uint64_t k = 0; k < dims.bytes; k += 4) {
    const auto d = static_cast<std::int32_t>(load_u32(dims.data + k, swap));
    if (d < 0)
      throw Damage(who + ": its dimension " + std::to_string(k / 4 + 1) + " is negative (" + std::to_string(d) + ")");
    a.dims.push_back(static_cast<std::size_t>(d));
  }
  const Element name = next(s, swap, who, "name");
  if (name.type != kMiInt8 && name.type != kMiUtf8 && name.bytes > 0)
    throw Damage(who + ": its name is not text (type " + std::to_string(name.type) + ")");
  a.name.assign(reinterpret_cast<const char*>(name.data), name.bytes);
  while (!a.name.empty() && a.name.back() == '\0') a.name.pop_back();
  return a;
}

// The array in `s` (a miMATRIX element's data) with its content; `who` names it.
MatArray array(Span s, bool swap, const std::string& who, int depth) {
  if (s.n == 0) {  // an empty cell: a miMATRIX element of no bytes
    MatArray a;
    a.type = "double";
    a.dims = {0, 0};
    return a;
  }
  if (depth > kMaxDepth)
    throw Damage(who + " is nested more than " + std::to_string(kMaxDepth) + " levels deep (dynid reads at most that)");
  std::uint32_t cls = 0;
  bool logical = false;
  MatArray a = header(&s, swap, who, &cls, &logical);
  const long double n = element_count(a);
  if (cls == kChar) {
    a.text = text_of(next(&s, swap, who, "text"), swap, who, a, n);
  } else if (cls >= kDouble && cls <= kUint64) {
    a.values = values_of(next(&s, swap, who, "real data"), n, swap, who, "real data", shape_of(a));
  } else if (cls == kSparse) {
    if (a.dims.size() != 2) throw Damage(who + ": a sparse array of " + std::to_string(a.dims.size()) + " dimensions");
    a.ir = indices_of(next(&s, swap, who, "sparse row indices (ir)"), swap, who, "sparse row indices (ir)");
    a.jc = indices_of(next(&s, swap, who, "sparse column pointers (jc)"), swap, who, "sparse column pointers (jc)");
    const std::size_t cols = a.dims[1];
    if (a.jc.size() < cols + 1)
      throw Damage(who + ": its " + std::to_string(a.jc.size()) + " sparse column pointers (jc) are fewer than its " +
                   std::to_string(cols) + " columns + 1");
    a.jc.resize(cols + 1);
    if (s.n == 0 && logical)
      a.values.assign(a.ir.size(), 1.0);  // a logical sparse array may hold no values: its nonzeros are true
    else
      a.values = values_of(next(&s, swap, who, "sparse values"), -1, swap, who, "sparse values", "");
  } else if (cls == kCell) {
    if (n * 8 > static_cast<long double>(s.n))
      throw Damage(who + ": its dimensions " + shape_of(a) + " declare " +
                   (n < 1e19L ? std::to_string(static_cast<std::uint64_t>(n)) : std::string("more than 10^19")) +
                   " cells where the array holds " + std::to_string(s.n) + " bytes, room for " +
                   std::to_string(s.n / 8) + " at most");
    a.cells.reserve(static_cast<std::size_t>(n));
    for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
      const std::string cell = who + " cell " + std::to_string(k + 1);
      const Element e = next(&s, swap, cell, "array element");
      if (e.bytes > 0 && e.type != kMiMatrix)
        throw Damage(cell + " is not an array element (MAT-file data type " + std::to_string(e.type) + ")");
      a.cells.push_back(array(Span{e.data, e.bytes}, swap, cell, depth + 1));
    }
  } else if (cls == kStruct || cls == kObject || cls == kFunction || cls == kOpaque) {
    // Listed, not read: no dynid input is a struct, an object or a function handle.
  }
  return a;
}

// Inflates the zlib stream of `packed` bytes at `offset` of `in` until `want` bytes came out or the stream ended;
// `broken` says why it stopped short ("" when it ended or gave `want`).
std::vector<unsigned char> inflate_from(std::ifstream& in, std::uint64_t offset, std::uint64_t packed,
                                        std::uint64_t want, std::string* broken) {
  std::vector<unsigned char> out;
  z_stream z{};
  if (inflateInit(&z) != Z_OK) {
    *broken = "zlib could not start";
    return out;
  }
  in.clear();
  in.seekg(static_cast<std::streamoff>(offset));
  std::array<unsigned char, 1 << 16> chunk;
  std::uint64_t left = packed;
  int rc = Z_OK;
  while (out.size() < want && rc == Z_OK) {
    if (z.avail_in == 0) {
      const std::uint64_t take = std::min<std::uint64_t>(left, chunk.size());
      if (take == 0 || !in.read(reinterpret_cast<char*>(chunk.data()), static_cast<std::streamsize>(take))) {
        *broken = "the compressed data end before their stream does";
        break;
      }
      left -= take;
      z.next_in = chunk.data();
      z.avail_in = static_cast<uInt>(take);
    }
    const std::size_t have = out.size();
    const std::uint64_t room = std::min<std::uint64_t>(want - have, 1 << 20);
    out.resize(have + room);
    z.next_out = out.data() + have;
    z.avail_out = static_cast<uInt>(room);
    rc = inflate(&z, Z_NO_FLUSH);
    out.resize(have + room - z.avail_out);
    if (rc == Z_BUF_ERROR && z.avail_in == 0) rc = Z_OK;  // wants more input
    if (rc != Z_OK && rc != Z_STREAM_END)
      *broken = std::string("zlib: ") + (z.msg ? z.msg : "error " + std::to_string(rc));
  }
  inflateEnd(&z);
  return out;
}

}  // namespace

std::string dims_text(const std::vector<std::size_t>& dims) {
  std::string s;
  for (std::size_t d : dims) s += (s.empty() ? "" : " x ") + std::to_string(d);
  return s.empty() ? "0 x 0" : s;
}

unsigned mat_header_version(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[128];
  if (!in.read(reinterpret_cast<char*>(h), 128)) return 0;
  const bool little = h[126] == 'I' && h[127] == 'M', big = h[126] == 'M' && h[127] == 'I';
  if (!little && !big) return 0;
  return little ? (h[125] << 8 | h[124]) : (h[124] << 8 | h[125]);
}

MatV5Reader::MatV5Reader(std::string path) : path_(std::move(path)) {
  std::ifstream in(path_, std::ios::binary);
  unsigned char h[128];
  if (!in.read(reinterpret_cast<char*>(h), 128))
    throw InputError(path_ + ": not a MATLAB v5 file (no 128-byte header)");
  swap_ = h[126] == 'M';
  in.seekg(0, std::ios::end);
  const auto file_size = static_cast<std::uint64_t>(in.tellg());
  for (std::uint64_t pos = 128; pos + 8 <= file_size;) {
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    unsigned char tag[8];
    if (!in.read(reinterpret_cast<char*>(tag), 8)) break;
    const std::uint32_t type = load_u32(tag, swap_), bytes = load_u32(tag + 4, swap_);
    if (type >> 16) break;  // a small element at the top level: no more variables
    Entry e{pos + 8, std::min<std::uint64_t>(bytes, file_size - pos - 8), type == kMiCompressed};
    const std::string who = "the variable at byte " + std::to_string(pos);
    pos += 8 + static_cast<std::uint64_t>(bytes);  // as libmatio and MATLAB go on: the declared bytes, unpadded
    if (type != kMiMatrix && type != kMiCompressed) continue;
    std::vector<unsigned char> head;
    std::string broken;
    if (e.compressed) {
      head = inflate_from(in, e.offset, e.bytes, kHeaderBytes + 8, &broken);
      if (head.size() < 8 || load_u32(head.data(), swap_) != kMiMatrix) continue;  // no array inside: not a variable
      head.erase(head.begin(), head.begin() + 8);
    } else {
      head.resize(std::min<std::uint64_t>(e.bytes, kHeaderBytes));
      in.seekg(static_cast<std::streamoff>(e.offset));
      in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
    }
    try {
      Span s{head.data(), head.size()};
      std::uint32_t cls = 0;
      bool logical = false;
      headers_.push_back(header(&s, swap_, who, &cls, &logical));
    } catch (const Damage& d) {
      throw InputError(path_ + ": " + d.what() + (broken.empty() ? "" : " (" + broken + ")") +
                       ": the file is damaged; save it again from MATLAB or SciPy");
    }
    entries_.push_back(e);
  }
}

MatArray MatV5Reader::read(std::size_t k) const {
  const Entry& e = entries_.at(k);
  const std::string who = "variable '" + headers_[k].name + "'";
  std::ifstream in(path_, std::ios::binary);
  std::vector<unsigned char> data;
  std::string broken;
  if (e.compressed) {
    std::vector<unsigned char> tag = inflate_from(in, e.offset, e.bytes, 8, &broken);
    const std::uint64_t declared = tag.size() == 8 ? load_u32(tag.data() + 4, swap_) : 0;
    data = inflate_from(in, e.offset, e.bytes, 8 + declared, &broken);
    data.erase(data.begin(), data.begin() + std::min<std::size_t>(8, data.size()));
    // A stream that ends cleanly ends the array, whatever its tag declared: libmatio 1.5.23 declares a compressed
    // char array's text with its padding twice (64 bytes for 56; MatV5Reader.AgreesWithLibmatioOnFilesLibmatioWrote).
  } else {
    data.resize(e.bytes);
    in.seekg(static_cast<std::streamoff>(e.offset));
    if (!in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size())))
      throw InputError(path_ + ": " + who + ": cannot be read (the file changed or ends early)");
  }
  try {
    if (!broken.empty()) throw Damage(who + ": its compressed data are damaged (" + broken + ")");
    return array(Span{data.data(), data.size()}, swap_, who, 0);
  } catch (const Damage& d) {
    throw InputError(path_ + ": " + d.what() + ": the file is damaged; save it again from MATLAB or SciPy");
  }
}

}  // namespace dynid::internal

// Gmsh .msh reader (MSH 2.2 and 4.1, ASCII and binary). See dynid/io/mesh_files.hpp and the Gmsh reference
// manual, "MSH file format". One cursor reads numbers either as text tokens or as raw binary values, so the
// 4.1 sections share one parser for both file types.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <set>
#include <unordered_map>

#include "dynid/io/mesh_files.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/text_util.hpp"

namespace dynid {

namespace {

/// Nodes per element of the Gmsh element types 1..31 (0: unknown to dynid).
int nodes_per_element(long long type) {
  static const int n[] = {0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13, 9, 10, 12, 15, 15, 21,
                          4, 5, 6, 20, 35, 56};
  return type >= 0 && type < static_cast<long long>(std::size(n)) ? n[type] : 0;
}

/// Dimension of a Gmsh element type (point 0, lines 1, surfaces 2, volumes 3).
int element_dimension(long long type) {
  if (type == 15) return 0;
  if (type == 1 || type == 8 || (type >= 26 && type <= 28)) return 1;
  if (type == 2 || type == 3 || type == 9 || type == 10 || type == 16 || (type >= 20 && type <= 25)) return 2;
  return 3;
}

std::string type_name(long long type) {
  switch (type) {
    case 2: return "3-node triangle";
    case 3: return "4-node quadrangle";
    case 4: return "4-node tetrahedron";
    case 5: return "8-node hexahedron";
    case 8: return "3-node line";
    case 9: return "6-node triangle";
    default: return "type " + std::to_string(type);
  }
}

/// Reads numbers from the file: as text tokens (ASCII) or raw values (binary), with positions for messages.
class Cursor {
 public:
  Cursor(std::string file, std::string data) : file_(std::move(file)), data_(std::move(data)) {}

  const std::string& file() const { return file_; }
  bool binary() const { return binary_; }
  void set_binary(bool on) { binary_ = on; }
  std::size_t remaining() const { return data_.size() - pos_; }

  /// "file:line" of the last token (ASCII) or "file: byte N" (binary data).
  std::string here() const {
    return binary_ ? file_ + ": byte " + std::to_string(start_) : file_ + ":" + std::to_string(token_line_);
  }
  [[noreturn]] void fail(const std::string& msg) const { throw InputError(here() + ": " + msg); }

  /// The next whitespace-separated token ("" at the end of the file).
  std::string token() {
    for (; pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_])); ++pos_)
      if (data_[pos_] == '\n') ++line_;
    start_ = pos_;
    token_line_ = line_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    return data_.substr(start_, pos_ - start_);
  }
  /// Whether another token follows on the current line (ASCII).
  bool more_on_line() {
    while (pos_ < data_.size() && (data_[pos_] == ' ' || data_[pos_] == '\t' || data_[pos_] == '\r')) ++pos_;
    return pos_ < data_.size() && data_[pos_] != '\n';
  }
  /// The rest of the current line (ASCII), without the line break.
  std::string rest_of_line() {
    const std::size_t e = std::min(data_.find('\n', pos_), data_.size());
    std::string s = data_.substr(pos_, e - pos_);
    pos_ = e;
    return s;
  }

  /// An integer: a text token, or a binary value of `bytes` bytes (4: int, 8: size_t).
  long long integer(const std::string& what, int bytes) {
    if (binary_) {
      if (bytes == 4) return raw<std::int32_t>(what);
      const std::uint64_t v = raw<std::uint64_t>(what);
      if (v > static_cast<std::uint64_t>(INT64_MAX)) fail(what + ": value " + std::to_string(v) + " out of range");
      return static_cast<long long>(v);
    }
    const std::string t = text(what);
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (*end != '\0' || errno != 0) fail(what + ": expected an integer, found '" + t + "'");
    return v;
  }
  double real(const std::string& what) {
    if (binary_) return raw<double>(what);
    const std::string t = text(what);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (*end != '\0' || !std::isfinite(v)) fail(what + ": expected a number, found '" + t + "'");
    return v;
  }
  /// A count of entries declared by the file; checked against the bytes left, so that no declared size is
  /// trusted before the file can hold it (each entry needs `numbers` text numbers or `bytes` binary bytes).
  long long count(const std::string& what, int binary_bytes_of_count, int numbers, std::size_t bytes) {
    const long long n = integer(what, binary_bytes_of_count);
    const std::size_t per = std::max<std::size_t>(binary_ ? bytes : 2 * static_cast<std::size_t>(numbers), 1);
    if (n < 0 || static_cast<unsigned long long>(n) > remaining() / per)
      fail(what + " is " + std::to_string(n) + ", but only " + std::to_string(remaining()) +
           " bytes follow (a corrupt or truncated file?)");
    return n;
  }

  /// Binary data starts right after the line break that ends the text before it.
  void begin_binary() {
    if (pos_ < data_.size() && data_[pos_] == '\r') ++pos_;
    if (pos_ >= data_.size() || data_[pos_] != '\n') fail("expected a line break before the binary data");
    ++pos_;
    binary_ = true;
  }

  /// Expects `$End<name>`.
  void expect_end(const std::string& name) {
    if (binary_) line_ = static_cast<int>(std::count(data_.begin(), data_.begin() + static_cast<std::ptrdiff_t>(pos_), '\n')) + 1;
    binary_ = false;
    const std::string t = token();
    if (t != "$End" + name)
      fail("$" + name + ": expected $End" + name + ", found " + (t.empty() ? "the end of the file" : "'" + t + "'") +
           " (the section holds more or less data than it declares)");
  }
  /// Skips a section this reader does not use, up to and including `$End<name>`.
  void skip_section(const std::string& name) {
    const std::size_t e = data_.find("$End" + name, pos_);
    if (e == std::string::npos) fail("$" + name + " has no $End" + name);
    line_ += static_cast<int>(std::count(data_.begin() + static_cast<std::ptrdiff_t>(pos_), data_.begin() + static_cast<std::ptrdiff_t>(e), '\n'));
    pos_ = e + 4 + name.size();
  }

 private:
  std::string text(const std::string& what) {
    std::string t = token();
    if (t.empty()) fail(what + ": the file ends here (truncated?)");
    if (t[0] == '$') fail(what + ": expected a number, found '" + t + "' (the section is truncated)");
    return t;
  }
  template <class T>
  T raw(const std::string& what) {
    start_ = pos_;
    if (remaining() < sizeof(T)) fail(what + ": the file ends inside the binary data (truncated)");
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }

  std::string file_, data_;
  std::size_t pos_ = 0, start_ = 0;  // read position; start of the last token or binary value
  int line_ = 1, token_line_ = 1;    // line at pos_ and of the last token (text only)
  bool binary_ = false;
};

class GmshReader {
 public:
  GmshReader(const std::string& path, std::string data) : c_(path, std::move(data)) { out_.file = path; }

  MeshData read() {
    for (std::string t = c_.token(); !t.empty(); t = c_.token()) {
      if (t[0] != '$') c_.fail("expected a section name such as $Nodes, found '" + t + "'");
      const std::string name = t.substr(1);
      if (name != "MeshFormat" && version_ == 0) c_.fail("$MeshFormat must come first (is this a Gmsh .msh file?)");
      if (name == "MeshFormat") mesh_format();
      else if (name == "PhysicalNames") physical_names();
      else if (name == "Entities" && version_ > 4) entities();
      else if (name == "Nodes") nodes();
      else if (name == "Elements") elements();
      else {
        out_.skipped.push_back("section $" + name);
        c_.skip_section(name);
      }
    }
    if (version_ == 0) throw InputError(out_.file + ": empty file, or not a Gmsh .msh file");
    if (!have_nodes_ || !have_elements_) throw InputError(out_.file + ": no $Nodes or no $Elements section");
    for (const auto& [type, n] : skipped_types_)
      out_.skipped.push_back(std::to_string(n) + " element" + (n == 1 ? "" : "s") + " of " + type_name(type) +
                             " (only 2-node lines and points are used)");
    return std::move(out_);
  }

 private:
  void mesh_format() {
    const std::string v = c_.token();
    if (v != "2.2" && v != "4.1") c_.fail("MSH version '" + v + "' is not supported (2.2 and 4.1 are; save with Gmsh's Mesh.MshFileVersion)");
    version_ = v == "2.2" ? 2.2 : 4.1;
    const long long type = c_.integer("$MeshFormat file-type", 4);
    if (type != 0 && type != 1) c_.fail("$MeshFormat: file-type must be 0 (ASCII) or 1 (binary), found " + std::to_string(type));
    const long long size = c_.integer("$MeshFormat data-size", 4);
    if (size != 8) c_.fail("$MeshFormat: data-size " + std::to_string(size) + " is not supported (8 is)");
    binary_ = type == 1;
    if (binary_) {
      c_.begin_binary();
      const long long one = c_.integer("$MeshFormat endianness marker", 4);
      if (one != 1)
        c_.fail("$MeshFormat: the binary endianness marker reads " + std::to_string(one) + ", not 1: the file was " +
                (one == 0x01000000 ? "written on a machine of the other byte order" : "corrupted") +
                "; save it as ASCII (Mesh.Binary = 0) or on a machine of this byte order");
    }
    c_.expect_end("MeshFormat");
  }

  void physical_names() {
    const long long n = c_.count("$PhysicalNames count", 4, 3, 0);
    for (long long i = 0; i < n; ++i) {
      const int dim = static_cast<int>(c_.integer("physical name dimension", 4));
      const int tag = static_cast<int>(c_.integer("physical name tag", 4));
      std::string name = c_.rest_of_line();
      const auto a = name.find('"'), b = name.rfind('"');
      if (a == std::string::npos || b == a) c_.fail("$PhysicalNames: the name of group " + std::to_string(tag) + " must be in double quotes");
      name = name.substr(a + 1, b - a - 1);
      names_[{dim, tag}] = name;
      out_.groups[name];  // named groups exist even when empty
    }
    c_.expect_end("PhysicalNames");
  }

  std::vector<int> physical_tags() {
    const long long n = c_.count("number of physical tags", 8, 1, 4);
    std::vector<int> tags;
    for (long long i = 0; i < n; ++i) tags.push_back(static_cast<int>(c_.integer("physical tag", 4)));
    return tags;
  }

  void entities() {
    if (binary_) c_.begin_binary();
    long long n[4];
    for (long long& k : n) k = c_.count("$Entities count", 8, 5, 36);
    for (int dim = 0; dim < 4; ++dim) {
      for (long long i = 0; i < n[dim]; ++i) {
        const int tag = static_cast<int>(c_.integer("entity tag", 4));
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) c_.real("entity coordinate");
        entity_groups_[{dim, tag}] = physical_tags();
        if (dim > 0) {
          const long long nb = c_.count("number of bounding entities", 8, 1, 4);
          for (long long k = 0; k < nb; ++k) c_.integer("bounding entity", 4);
        }
      }
    }
    c_.expect_end("Entities");
  }

  void add_node(long long id, const Eigen::Vector3d& x) {
    if (id < 1 || id > INT32_MAX) c_.fail("node tag " + std::to_string(id) + " out of range");
    if (!node_ids_.insert(static_cast<int>(id)).second) c_.fail("node " + std::to_string(id) + " is defined twice");
    out_.nodes.push_back({static_cast<int>(id), x});
  }
  Eigen::Vector3d coordinates(long long id) {
    Eigen::Vector3d x;
    for (int k = 0; k < 3; ++k) x[k] = c_.real("node " + std::to_string(id) + " coordinate");
    return x;
  }

  /// The header of a 4.1 $Nodes or $Elements section: the number of entity blocks (returned), the number of
  /// entries (*total; each at least `numbers` text numbers or `bytes` binary bytes), the minimum and maximum tag.
  long long block_header(const std::string& section, const std::string& entries, int numbers, std::size_t bytes,
                         long long* total) {
    if (binary_) c_.begin_binary();
    const long long blocks = c_.count(section + ": number of entity blocks", 8, 4, 20);
    *total = c_.count(section + ": number of " + entries, 8, numbers, bytes);
    c_.integer(section + ": minimum tag", 8);
    c_.integer(section + ": maximum tag", 8);
    return blocks;
  }

  void nodes() {
    if (have_nodes_) c_.fail("a second $Nodes section (only one is supported)");
    have_nodes_ = true;
    if (version_ < 4) {
      const long long n = c_.count("$Nodes: number of nodes", 8, 4, 28);
      if (binary_) c_.begin_binary();
      for (long long i = 0; i < n; ++i) {
        const long long id = c_.integer("$Nodes: node " + std::to_string(i + 1) + " of " + std::to_string(n), 4);
        add_node(id, coordinates(id));
      }
      c_.expect_end("Nodes");
      return;
    }
    long long total = 0;
    const long long blocks = block_header("$Nodes", "nodes", 4, 32, &total);
    for (long long b = 0; b < blocks; ++b) {
      const int dim = static_cast<int>(c_.integer("$Nodes: entity dimension", 4));
      c_.integer("$Nodes: entity tag", 4);
      const bool parametric = c_.integer("$Nodes: parametric flag", 4) != 0;
      const long long n = c_.count("$Nodes: nodes in block", 8, 4, 32);
      if (static_cast<long long>(out_.nodes.size()) + n > total)
        c_.fail("$Nodes: the blocks hold more nodes than the " + std::to_string(total) + " declared");
      std::vector<long long> ids;
      for (long long i = 0; i < n; ++i) ids.push_back(c_.integer("$Nodes: node tag", 8));
      for (long long id : ids) {
        const Eigen::Vector3d x = coordinates(id);
        for (int k = 0; parametric && k < dim; ++k) c_.real("node " + std::to_string(id) + " parametric coordinate");
        add_node(id, x);
      }
    }
    if (static_cast<long long>(out_.nodes.size()) != total)
      c_.fail("$Nodes declares " + std::to_string(total) + " nodes but its blocks hold " + std::to_string(out_.nodes.size()));
    c_.expect_end("Nodes");
  }

  /// One element: its tag and node tags have been read; `groups` are its physical groups' names.
  void add_element(long long tag, long long type, const std::vector<long long>& nodes,
                   const std::vector<std::string>& groups, const std::string& where) {
    if (tag < 1 || tag > INT32_MAX) c_.fail("element tag " + std::to_string(tag) + " out of range");
    for (long long id : nodes)
      if (id < 1 || id > INT32_MAX || !node_ids_.count(static_cast<int>(id)))
        throw InputError(where + ": element " + std::to_string(tag) + ": node " + std::to_string(id) +
                         " does not exist (it is not in $Nodes)");
    for (const std::string& g : groups) {
      MeshGroup& grp = out_.groups[g];
      for (long long id : nodes) grp.nodes.push_back(static_cast<int>(id));
      if (type == 1) grp.elements.push_back(static_cast<int>(tag));
    }
    if (type == 15) return;
    if (type != 1) {
      ++skipped_types_[type];
      return;
    }
    if (!element_ids_.insert(static_cast<int>(tag)).second)
      throw InputError(where + ": element " + std::to_string(tag) + " is defined twice");
    MeshElement e;
    e.id = static_cast<int>(tag);
    e.nodes = {{static_cast<int>(nodes[0]), static_cast<int>(nodes[1])}};
    if (!groups.empty()) e.group = groups.front();
    e.where = where;
    out_.elements.push_back(e);
  }

  std::vector<std::string> group_names(int dim, const std::vector<int>& tags) {
    std::vector<std::string> g;
    for (int t : tags) {
      auto it = names_.find({dim, t});
      g.push_back(it != names_.end() ? it->second : std::to_string(t));
    }
    return g;
  }

  /// The node tags of one element of `type` (unknown types: the rest of the line, ASCII only).
  std::vector<long long> element_nodes(long long tag, long long type, int bytes) {
    std::vector<long long> nodes;
    const int nn = nodes_per_element(type);
    const std::string what = "element " + std::to_string(tag) + " node";
    if (nn == 0) {
      if (c_.binary()) c_.fail("element " + std::to_string(tag) + ": element type " + std::to_string(type) +
                               " is unknown to dynid and cannot be skipped in binary data; save the mesh as ASCII");
      while (c_.more_on_line()) nodes.push_back(c_.integer(what, bytes));
      return nodes;
    }
    for (int k = 0; k < nn; ++k) nodes.push_back(c_.integer(what, bytes));
    return nodes;
  }

  void elements() {
    if (!have_nodes_) c_.fail("$Elements before $Nodes (nodes must come first)");
    if (have_elements_) c_.fail("a second $Elements section (only one is supported)");
    have_elements_ = true;
    if (version_ < 4) return elements22();
    long long total = 0;
    const long long blocks = block_header("$Elements", "elements", 2, 16, &total);
    long long read = 0;
    for (long long b = 0; b < blocks; ++b) {
      const int dim = static_cast<int>(c_.integer("$Elements: entity dimension", 4));
      const int entity = static_cast<int>(c_.integer("$Elements: entity tag", 4));
      const long long type = c_.integer("$Elements: element type", 4);
      const long long n = c_.count("$Elements: elements in block", 8, 2, 16);
      if ((read += n) > total) c_.fail("$Elements: the blocks hold more elements than the " + std::to_string(total) + " declared");
      auto it = entity_groups_.find({dim, entity});
      const std::vector<std::string> groups =
          group_names(dim, it != entity_groups_.end() ? it->second : std::vector<int>{});
      for (long long i = 0; i < n; ++i) {
        const long long tag = c_.integer("$Elements: element tag", 8);
        const std::string where = c_.here();
        add_element(tag, type, element_nodes(tag, type, 8), groups, where);
      }
    }
    if (read != total) c_.fail("$Elements declares " + std::to_string(total) + " elements but its blocks hold " + std::to_string(read));
    c_.expect_end("Elements");
  }

  /// MSH 2.2: each element carries its tags (physical group first, then elementary entity).
  void elements22() {
    const long long total = c_.count("$Elements: number of elements", 8, 4, 16);
    if (binary_) c_.begin_binary();
    for (long long read = 0; read < total;) {
      long long type = 0, n = 1, ntags = 0;
      if (binary_) {  // a header per run of elements of one type: type, count, number of tags
        type = c_.integer("$Elements: element type", 4);
        n = c_.integer("$Elements: elements following", 4);
        ntags = c_.integer("$Elements: number of tags", 4);
        if (n < 1 || n > total - read) c_.fail("$Elements: a block of " + std::to_string(n) + " elements does not fit the declared " + std::to_string(total));
      }
      for (long long i = 0; i < n; ++i, ++read) {
        const long long tag = c_.integer("$Elements: element " + std::to_string(read + 1) + " of " + std::to_string(total), 4);
        const std::string where = c_.here();
        if (!binary_) {
          type = c_.integer("element " + std::to_string(tag) + " type", 4);
          ntags = c_.integer("element " + std::to_string(tag) + " number of tags", 4);
        }
        if (ntags < 0 || ntags > 64) c_.fail("element " + std::to_string(tag) + ": " + std::to_string(ntags) + " tags is not plausible");
        std::vector<int> tags;
        for (long long k = 0; k < ntags; ++k) tags.push_back(static_cast<int>(c_.integer("element tag", 4)));
        std::vector<int> physical;
        if (!tags.empty() && tags[0] != 0) physical.push_back(tags[0]);
        add_element(tag, type, element_nodes(tag, type, 4), group_names(element_dimension(type), physical), where);
      }
    }
    c_.expect_end("Elements");
  }

  Cursor c_;
  MeshData out_;
  double version_ = 0;
  bool binary_ = false, have_nodes_ = false, have_elements_ = false;
  std::map<std::pair<int, int>, std::string> names_;               // (dimension, physical tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_groups_;  // (dimension, entity tag) -> physical tags
  std::set<int> node_ids_, element_ids_;
  std::map<long long, long long> skipped_types_;  // element type -> count
};

}  // namespace

MeshData parse_gmsh(const std::string& bytes, const std::string& name) { return GmshReader(name, bytes).read(); }
MeshData read_gmsh(const std::string& path) { return parse_gmsh(internal::read_file_bytes(path), path); }

}  // namespace dynid

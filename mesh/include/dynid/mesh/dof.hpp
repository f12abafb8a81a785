// dynid/mesh/dof.hpp -- degree-of-freedom types and the map from (node, DOF type) to equation numbers.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dynid {

/// The six nodal DOF types, in the order they are numbered at a node.
/// Translations UX, UY, UZ in metres (model units); rotations RX, RY, RZ in radians about the global axes.
enum class Dof : std::uint8_t { UX = 0, UY = 1, UZ = 2, RX = 3, RY = 4, RZ = 5 };
inline constexpr int kNumDofTypes = 6;

/// A set of DOF types as a bit mask (bit i = Dof(i)).
using DofMask = std::uint8_t;
inline constexpr DofMask dof_bit(Dof d) { return static_cast<DofMask>(1u << static_cast<unsigned>(d)); }
inline constexpr DofMask kAllDofs = 0x3F;
inline constexpr DofMask kTranslations = 0x07;
inline constexpr DofMask kRotations = 0x38;
inline constexpr bool has_dof(DofMask m, Dof d) { return (m & dof_bit(d)) != 0; }
inline constexpr bool is_rotation(Dof d) { return static_cast<int>(d) >= 3; }

/// "ux", "uy", ... "rz".
std::string_view dof_name(Dof d);
/// Parses "ux".."rz" (case-insensitive). Returns false if the name is not a DOF type.
bool parse_dof(std::string_view name, Dof* out);
/// "ux,uy,rz" for a mask.
std::string dof_mask_string(DofMask m);

/// Equation numbering of a model: node-major, then DOF type in the order UX..RZ, counting only DOFs that are
/// active (used by some element) and not restrained. Restrained DOFs are eliminated (equation number -1).
/// This is the paper's numbering: node 1 owns DOFs 1, 2, 3 (ux, uy, rz) of a plane frame, node 2 owns 4, 5, 6...
class DofMap {
 public:
  DofMap() = default;
  /// active[n] = DOF types used at node n; restrained[n] = DOF types fixed at node n.
  DofMap(const std::vector<DofMask>& active, const std::vector<DofMask>& restrained);

  int num_free() const { return static_cast<int>(dof_node_.size()); }
  int num_nodes() const { return static_cast<int>(eq_.size()); }
  /// Equation number of DOF d at node n, or -1 if inactive or restrained.
  int eq(int node, Dof d) const { return eq_[node][static_cast<int>(d)]; }
  /// Node index and DOF type of equation i.
  int node_of(int i) const { return dof_node_[i]; }
  Dof type_of(int i) const { return dof_type_[i]; }
  DofMask active(int node) const { return active_[node]; }
  DofMask restrained(int node) const { return restrained_[node]; }

 private:
  std::vector<std::array<int, kNumDofTypes>> eq_;
  std::vector<DofMask> active_, restrained_;
  std::vector<int> dof_node_;
  std::vector<Dof> dof_type_;
};

}  // namespace dynid

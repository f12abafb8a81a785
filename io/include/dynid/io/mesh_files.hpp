// dynid/io/mesh_files.hpp -- meshes written by other programs: Gmsh .msh and an Abaqus .inp subset.
//
// A reader returns a MeshData: nodes, 2-node line elements and named groups (Gmsh physical groups; Abaqus
// *NSET/*ELSET), plus, from Abaqus, materials, sections, section assignments and *BOUNDARY conditions. The case
// file (`model: {file: ...}`, docs/case-file.md) turns it into a Model; what a reader does not use is listed in
// MeshData::skipped, never dropped silently.
//
//   Gmsh    MSH 2.2 and 4.1, ASCII and binary (little- or big-endian files are accepted only when they match
//           this machine: the endianness marker must read as 1). Sections $MeshFormat, $PhysicalNames,
//           $Entities (4.1: entity -> physical groups), $Nodes, $Elements; others are skipped. Line elements
//           (type 1) become dynid elements; points (type 15) only put their node into groups; other element
//           types are skipped, counted by type.
//   Abaqus  *NODE, *ELEMENT (TYPE=B21, B23 -> plane frame; B31, B33 -> space frame), *NSET, *ELSET (GENERATE),
//           *BEAM SECTION (SECTION=RECT, CIRC, PIPE), *BEAM GENERAL SECTION (SECTION=GENERAL), *MATERIAL with
//           *ELASTIC and *DENSITY, *BOUNDARY, *INCLUDE; comments (**), continuation lines, any letter case.
//           Abaqus's B21/B31 are shear-flexible (Timoshenko); dynid's frames are Euler-Bernoulli, so slender
//           members only agree.
//
// Every error is an InputError naming the file, the line (ASCII; a byte offset in binary data) and the entity.
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/io/limits.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

/// A 2-node line element of a mesh file (a dynid beam or frame element once sections are assigned).
struct MeshElement {
  int id = 0;
  std::array<int, 2> nodes{{0, 0}};     ///< node ids
  std::optional<ElementType> type;       ///< Abaqus: from TYPE=; Gmsh: unset (the case file decides)
  int section = -1, material = -1;       ///< indices into MeshData::sections / materials (Abaqus), or -1
  Eigen::Vector3d orientation = Eigen::Vector3d::Zero();  ///< Frame3D: a vector in the local x-z plane
  std::string group;                     ///< the first group it belongs to ("" if none)
  std::string where;                     ///< "file:line" (or "file: byte N") where it is defined
};

/// A named set: Gmsh physical group or Abaqus *NSET/*ELSET.
struct MeshGroup {
  std::vector<int> elements;  ///< ids of line elements in the group
  std::vector<int> nodes;     ///< ids of nodes in the group (nodes of all its elements, points, *NSET)
};

struct MeshData {
  std::string file;
  std::vector<Node> nodes;
  std::vector<MeshElement> elements;
  std::map<std::string, MeshGroup> groups;  ///< by name; Abaqus names in upper case (Abaqus ignores case)
  bool names_ignore_case = false;           ///< Abaqus: look groups up with find_group (case-insensitive)
  std::vector<Material> materials;          ///< Abaqus *MATERIAL (and *BEAM GENERAL SECTION's own)
  std::vector<Section> sections;            ///< Abaqus sections, named after their ELSET
  std::vector<std::pair<int, DofMask>> restraints;  ///< Abaqus *BOUNDARY: (node id, restrained DOF types)
  std::vector<std::string> skipped;         ///< what was read but not used, one human-readable line each

  /// The group with this name (case-insensitively for Abaqus), or null.
  const MeshGroup* find_group(const std::string& name) const;
  /// "base, beams, columns" (for messages).
  std::string group_names() const;
};

/// Reads a Gmsh .msh file (2.2 or 4.1, ASCII or binary). Throws InputError.
MeshData read_gmsh(const std::string& path);
/// Reads an Abaqus .inp file (the subset above). Throws InputError; a *NSET/*ELSET GENERATE line may make at most
/// `limits.max_generated_ids` ids.
MeshData read_abaqus(const std::string& path, const ReaderLimits& limits = {});
/// Parses a Gmsh .msh file held in memory: `bytes` is its content, `name` names it in messages.
MeshData parse_gmsh(const std::string& bytes, const std::string& name);
/// Parses an Abaqus .inp file held in memory. *INCLUDE files are read from `include_dir`; with include_dir ""
/// (the default) an *INCLUDE is an InputError, so that the result depends on `bytes` alone.
MeshData parse_abaqus(const std::string& bytes, const std::string& name, const std::string& include_dir = "",
                      const ReaderLimits& limits = {});
/// Reads a mesh file by its extension: .msh (Gmsh) or .inp (Abaqus).
MeshData read_mesh_file(const std::string& path, const ReaderLimits& limits = {});

}  // namespace dynid

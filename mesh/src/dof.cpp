#include "dynid/mesh/dof.hpp"

#include <cctype>

#include "dynid/mesh/error.hpp"

namespace dynid {

namespace internal {
void check_failed(const char* expr, const char* file, int line, const std::string& what) {
  throw InternalError(std::string("internal error (please report): ") + what + " [check '" + expr + "' failed at " +
                      file + ":" + std::to_string(line) + "]");
}
}  // namespace internal

namespace {
constexpr std::array<std::string_view, kNumDofTypes> kNames = {"ux", "uy", "uz", "rx", "ry", "rz"};
}

std::string_view dof_name(Dof d) { return kNames[static_cast<int>(d)]; }

bool parse_dof(std::string_view name, Dof* out) {
  if (name.size() != 2) return false;
  const char a = static_cast<char>(std::tolower(static_cast<unsigned char>(name[0])));
  const char b = static_cast<char>(std::tolower(static_cast<unsigned char>(name[1])));
  for (int i = 0; i < kNumDofTypes; ++i)
    if (kNames[i][0] == a && kNames[i][1] == b) {
      *out = static_cast<Dof>(i);
      return true;
    }
  return false;
}

std::string dof_mask_string(DofMask m) {
  std::string s;
  for (int i = 0; i < kNumDofTypes; ++i)
    if (m & (1u << i)) {
      if (!s.empty()) s += ',';
      s += kNames[i];
    }
  return s;
}

DofMap::DofMap(const std::vector<DofMask>& active, const std::vector<DofMask>& restrained)
    : eq_(active.size()), active_(active), restrained_(restrained) {
  DYNID_CHECK(active.size() == restrained.size(), "DofMap: active and restrained sizes differ");
  int next = 0;
  for (std::size_t n = 0; n < active.size(); ++n) {
    for (int d = 0; d < kNumDofTypes; ++d) {
      const bool free = (active[n] & (1u << d)) && !(restrained[n] & (1u << d));
      eq_[n][d] = free ? next++ : -1;
      if (free) {
        dof_node_.push_back(static_cast<int>(n));
        dof_type_.push_back(static_cast<Dof>(d));
      }
    }
  }
}

}  // namespace dynid

// Helpers shared by the JSON writers (results, discovery, identification); internal to io.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace dynid::internal {

/// An Eigen vector as a std::vector, which nlohmann::json writes as an array.
inline std::vector<double> vec(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

}  // namespace dynid::internal

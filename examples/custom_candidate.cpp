// examples/custom_candidate.cpp -- add your own kind of missing physics to dynid's discovery, in one file.
//
// The kind here is "rotary_inertia": a body fixed to a node whose rotary inertia the model leaves out (a motor, a
// disc, a heavy bracket at the tip of a beam). It is a mass-like effect on one rotation DOF:
//   dK(theta) = 0,   dM(theta) = theta J_ref on the node's rotation,   theta >= 0, nominal theta = 0,
// with J_ref = 1 % of the structure's mass times its length squared (a heavy-tailed prior of that median).
//
// A kind is two things: a class derived from dynid::Candidate (its parameter, its terms dK, dM with their
// derivatives, its values in physical units) and a dynid::CandidateKind (its name, its nature and how it places
// candidates on a model). A host code hands the kind to discover() in DiscoveryOptions::extra_kinds; a kind that
// ships with dynid is one file in engine/src/candidates/ plus one line in builtin_candidate_kinds()
// (engine/src/candidates/registry.cpp). check_candidate() (dynid/engine/candidate_checks.hpp) tests the invariants
// every candidate must satisfy: call it from your tests, as this program does before using the kind.
//
// The program builds a cantilever (10 Euler-Bernoulli elements), a "real" structure with a rotary inertia at the
// tip, six of its modes measured at the transverse DOFs, checks the new kind's candidates, and runs discovery with
// dynid's kinds and the new one. Exit code 0 when discovery names the new kind at the tip, 1 otherwise.
//   build/examples/custom_candidate          (built with the tree; ctest runs it: example.custom_candidate)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/candidate.hpp"
#include "dynid/engine/candidate_checks.hpp"
#include "dynid/engine/discovery.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/engine/modal_data.hpp"
#include "dynid/mesh/generators.hpp"

namespace {

using dynid::Candidate;
using dynid::CandidateContext;
using dynid::CandidateKind;
using dynid::CandidateParameter;
using dynid::CustomTerm;
using dynid::Dof;
using dynid::Model;
using dynid::PhysicalValue;

/// dM = theta J_ref on the rotation `dof` of the node with index `node`; dK = 0.
class RotaryInertia : public Candidate {
 public:
  RotaryInertia(const Model& m, int node, Dof dof, double j_ref)
      : id_(m.nodes()[node].id), eq_(m.dof_map().eq(node, dof)), j_ref_(j_ref) {}

  std::string kind() const override { return "rotary_inertia"; }
  dynid::Nature nature() const override { return dynid::Nature::kMass; }
  std::string description() const override { return "rotary inertia at node " + std::to_string(id_); }
  dynid::Site site() const override { return {{id_}, {}}; }

  // One parameter in units of J_ref: nominal 0 (the model as given), bounds [0, 100], heavy-tailed prior of median 1.
  std::vector<CandidateParameter> parameters() const override {
    return {{"inertia", 0.0, 0.0, 100.0, 1.0, CandidateParameter::Prior::kHeavyTailed}};
  }

  // The term lives on one equation (a node's own DOF is always in the sparsity pattern); it is linear in theta,
  // so its derivative is J_ref.
  std::vector<CustomTerm> terms(const Model&, int first) const override {
    CustomTerm t;
    t.dofs = {eq_};
    t.params = {first};
    const Eigen::MatrixXd J = Eigen::MatrixXd::Constant(1, 1, j_ref_);
    t.eval = [J](const Eigen::VectorXd& theta, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM,
                 std::vector<Eigen::MatrixXd>* dKd, std::vector<Eigen::MatrixXd>* dMd) {
      (void)dK;  // no stiffness: left empty (zero)
      if (dM) *dM = theta[0] * J;
      if (dKd) *dKd = {Eigen::MatrixXd()};
      if (dMd) *dMd = {J};
    };
    return {t};
  }

  std::vector<PhysicalValue> physical(const Eigen::VectorXd& theta, const Eigen::VectorXd& std) const override {
    return {{"rotary inertia", "kg m^2", j_ref_ * theta[0], j_ref_ * std[0]}};
  }

  std::string finding(const std::vector<PhysicalValue>& v) const override {
    char b[96];
    std::snprintf(b, sizeof b, "%.4g +- %.2g %s", v[0].value, v[0].std, v[0].unit.c_str());
    return "node " + std::to_string(id_) + " carries a rotary inertia the model leaves out: " + b;
  }

 private:
  int id_, eq_;
  double j_ref_;
};

/// The kind: one candidate per node that has elements and a free in-plane rotation.
CandidateKind rotary_inertia_kind() {
  CandidateKind k;
  k.name = "rotary_inertia";
  k.nature = dynid::Nature::kMass;
  k.summary = "a rotary inertia at a node (a body fixed there)";
  k.place = [](const CandidateContext& c) {
    const Model& m = *c.model;
    double length = 0;
    for (const dynid::Node& a : m.nodes())
      for (const dynid::Node& b : m.nodes()) length = std::max(length, (a.x - b.x).norm());
    const double j_ref = 0.01 * c.structure_mass * length * length;
    std::vector<std::unique_ptr<Candidate>> out;
    for (int n = 0; n < static_cast<int>(m.nodes().size()); ++n)
      if (c.node_used[n] && m.dof_map().eq(n, Dof::RZ) >= 0)
        out.push_back(std::make_unique<RotaryInertia>(m, n, Dof::RZ, j_ref));
    return out;
  };
  return k;
}

}  // namespace

int main() {
  // The model: a steel cantilever 2 m long, 10 elements (nodes 1..11, clamped at node 1).
  dynid::BeamSpec spec;
  spec.length = 2.0;
  spec.elements = 10;
  spec.material = {"steel", 210e9, 0, 0.3, 7850};
  spec.section.name = "bar";
  spec.section.A = 1e-3;
  spec.section.Iz = 2e-7;
  spec.support = dynid::BeamSupport::Cantilever;
  const Model model = dynid::make_beam(spec);

  // The real structure: the same beam with a disc at the tip (rotary inertia 0.05 kg m^2 on rz of node 11),
  // which the model leaves out.
  const double j_true = 0.05;
  Model truth = dynid::make_beam(spec);
  dynid::MatrixElementData disc;
  disc.dofs = {{11, Dof::RZ}};
  disc.K = Eigen::MatrixXd::Zero(1, 1);
  disc.M = Eigen::MatrixXd::Constant(1, 1, j_true);
  truth.add_element(dynid::make_matrix_element(100, std::move(disc), "disc"));
  truth.finalize();

  // The measurement: its first six modes at the transverse DOF of nodes 2..11 (exact values; the noise stated below
  // is what discovery weighs them with).
  std::vector<dynid::MeasuredDof> sensors;
  for (int id = 2; id <= 11; ++id) sensors.push_back({id, Dof::UY});
  dynid::EigenOptions eo;
  eo.num_modes = 6;
  const dynid::ModalResult modes = dynid::modal_analysis(truth, eo);
  if (!modes.ok()) {
    std::fprintf(stderr, "custom_candidate: modal analysis failed: %s\n", modes.summary.message.c_str());
    return 1;
  }
  const dynid::ModalData measured = dynid::sample_modes(truth, modes, sensors, 0, 6, "cantilever with a disc");

  // 1. The new kind's candidates satisfy the invariants (nominal = the model, derivatives, bounds, values).
  dynid::DiscoveryOptions options;
  options.extra_kinds = {rotary_inertia_kind()};
  int checked = 0;
  for (const auto& c : dynid::candidate_library(model, measured, options)) {
    if (c->kind() != "rotary_inertia") continue;
    const dynid::CandidateCheck r = dynid::check_candidate(model, *c);
    if (!r.ok()) {
      std::fprintf(stderr, "custom_candidate: %s fails its checks:\n%s\n", c->description().c_str(),
                   r.report().c_str());
      return 1;
    }
    ++checked;
  }
  std::printf("check_candidate: %d rotary_inertia candidates pass\n", checked);

  // 2. Discovery with dynid's kinds and the new one.
  options.frequency_noise = 0.001;
  options.shape_noise = 0.01;
  const dynid::DiscoverySummary s = dynid::discover(model, measured, options);
  std::printf("verdict: %s (%s)\n", dynid::to_string(s.verdict), dynid::to_string(s.reason));
  for (const dynid::ScoredHypothesis& h : s.findings) {
    std::printf("finding: %s, ln Bayes factor %.1f\n", h.description.c_str(), h.log_evidence);
    for (const PhysicalValue& v : h.values)
      std::printf("  %s = %.4g +- %.2g %s\n", v.name.c_str(), v.value, v.std, v.unit.c_str());
  }
  const bool found =
      s.verdict == dynid::Verdict::kMissingPhysics && !s.findings.empty() && s.findings[0].kind == "rotary_inertia" &&
      std::find(s.findings[0].site.nodes.begin(), s.findings[0].site.nodes.end(), 11) != s.findings[0].site.nodes.end();
  std::printf("%s\n", found ? "the new kind explains the data (true inertia 0.05 kg m^2)" : "NOT FOUND");
  return found ? 0 : 1;
}

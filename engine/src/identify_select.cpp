// Automatic mode selection: stability weights, mean-shift clusters over orders, evidence checks (see
// dynid/engine/identify.hpp, header comment, steps 1-3).
#include "internal/identify_select.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>

#include "dynid/engine/correlation.hpp"

namespace dynid::internal {

namespace {

// Full weight up to the tolerance, falling linearly to 0 at twice it: continuous, so rounding cannot flip it.
double ramp(double x) { return std::clamp(2.0 - x, 0.0, 1.0); }
// The window of a cluster: flat over its inner half, to 0 at its edge (u = |f - fc| / (tol fc)).
double window(double u) { return std::clamp(2.0 * (1.0 - u), 0.0, 1.0); }

struct Cand {
  int pole;  // index in s.poles
  int j, p;  // order index, pole index
  double f, w;
};
}  // namespace

std::vector<RawPole> discrete_poles(const Eigen::MatrixXd& A, double dt, double decay, const Eigen::MatrixXd& output) {
  std::vector<RawPole> poles;
  Eigen::EigenSolver<Eigen::MatrixXd> es(A);
  if (es.info() != Eigen::Success) return poles;
  for (Eigen::Index k = 0; k < A.rows(); ++k) {
    const std::complex<double> mu = es.eigenvalues()[k];
    if (mu.imag() <= 0 || std::abs(mu) == 0) continue;
    RawPole rp;
    rp.lambda = std::log(mu) / dt + decay;
    rp.vec = output * es.eigenvectors().col(k);
    poles.push_back(std::move(rp));
  }
  return poles;
}

double pole_hz(std::complex<double> l) { return std::abs(l) / (2 * M_PI); }
double pole_zeta(std::complex<double> l) { return -l.real() / std::abs(l); }
double complex_mac(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b) {
  const double d = a.squaredNorm() * b.squaredNorm();
  return d > 0 ? std::norm(a.dot(b)) / d : 0.0;
}
std::complex<double> pole_of(double f, double zeta) {
  const double w = 2 * M_PI * f;
  return {-zeta * w, w * std::sqrt(std::max(0.0, 1 - zeta * zeta))};
}

namespace {
// Step 1: the diagram (s.poles), with hard flags (drawn) and continuous weights (used); returns the poles with
// weight, ascending in frequency.
std::vector<Cand> weighted_poles(const std::vector<std::vector<RawPole>>& orders, const std::vector<int>& order_of,
                                 double lo, double hi, const IdentificationOptions& o, IdentificationSummary& s) {
  std::vector<Cand> cand;
  for (std::size_t j = 0; j < orders.size(); ++j)
    for (std::size_t p = 0; p < orders[j].size(); ++p) {
      const RawPole& rp = orders[j][p];
      StabilizationPole sp;
      sp.order = order_of[j];
      sp.frequency_hz = pole_hz(rp.lambda);
      sp.damping_ratio = pole_zeta(rp.lambda);
      sp.physical = sp.frequency_hz >= lo && sp.frequency_hz <= hi && sp.damping_ratio > 0 && sp.damping_ratio < o.max_damping;
      if (j > 0 && !orders[j - 1].empty()) {
        // The pole of the previous order it continues: the one it matches best in frequency, damping and vector
        // (the stability weight's maximum over them; the nearest in frequency when it matches none). Of a closely
        // spaced pair, the nearest in frequency may be the other mode's pole.
        const double edge = 0.01 * sp.frequency_hz;
        const double phys = sp.frequency_hz > 0 && sp.damping_ratio > 0
                                ? std::clamp((o.max_damping - sp.damping_ratio) / (0.25 * o.max_damping), 0.0, 1.0) *
                                      std::clamp((sp.frequency_hz - lo) / edge + 0.5, 0.0, 1.0) *
                                      std::clamp((hi - sp.frequency_hz) / edge + 0.5, 0.0, 1.0)
                                : 0.0;
        struct Match {
          double df = 1e300, dz = 0, mac = 0, w = 0;
        } best, nearest;
        for (const RawPole& q : orders[j - 1]) {
          Match m;
          m.df = std::abs(pole_hz(q.lambda) - sp.frequency_hz) / sp.frequency_hz;
          m.dz = std::abs(pole_zeta(q.lambda) - sp.damping_ratio) / std::max(std::abs(sp.damping_ratio), 1e-12);
          m.mac = rp.vec.size() <= 1 ? 1.0 : complex_mac(rp.vec, q.vec);
          m.w = phys * ramp(m.df / o.stable_frequency) * ramp(m.dz / o.cluster_damping) *
                ramp((1 - m.mac) / std::max(1 - o.stable_mac, 1e-12));
          if (m.w > best.w) best = m;
          if (m.df < nearest.df) nearest = m;
        }
        const Match& m = best.w > 0 ? best : nearest;
        sp.weight = best.w;
        sp.damping_change = m.dz;
        sp.stable_frequency = m.df <= o.stable_frequency;
        sp.stable_damping = m.dz <= o.stable_damping;
        sp.stable_vector = m.mac >= o.stable_mac;
      }
      if (sp.weight > 0)
        cand.push_back({static_cast<int>(s.poles.size()), static_cast<int>(j), static_cast<int>(p), sp.frequency_hz, sp.weight});
      s.poles.push_back(sp);
    }
  std::sort(cand.begin(), cand.end(), [](const Cand& a, const Cand& b) { return a.f < b.f || (a.f == b.f && a.pole < b.pole); });
  return cand;
}
}  // namespace

namespace {
// Step 2: mean shift from every candidate to a maximum of the weighted density; converged points within a quarter
// window of each other are one centre (their weighted mean). Sorted by frequency.
std::vector<double> density_centres(const std::vector<Cand>& cand, double tol) {
  std::vector<double> fs(cand.size());
  for (std::size_t a = 0; a < cand.size(); ++a) fs[a] = cand[a].f;
  // Weighted mean of the candidates in the window around f.
  auto shift = [&](double f, double* mass) {
    const double h = tol * f;
    const auto b = std::lower_bound(fs.begin(), fs.end(), f - h) - fs.begin();
    const auto e = std::upper_bound(fs.begin(), fs.end(), f + h) - fs.begin();
    double sw = 0, swf = 0;
    for (auto a = b; a < e; ++a) {
      const double k = cand[static_cast<std::size_t>(a)].w * window(std::abs(cand[static_cast<std::size_t>(a)].f - f) / h);
      sw += k, swf += k * cand[static_cast<std::size_t>(a)].f;
    }
    *mass = sw;
    return sw > 0 ? swf / sw : f;
  };
  std::vector<std::pair<double, double>> tops;  // (converged frequency, weight of the start)
  for (const Cand& c : cand) {
    double f = c.f, mass = 0;
    for (int it = 0; it < 200; ++it) {
      const double g = shift(f, &mass);
      const bool done = std::abs(g - f) <= 1e-10 * f;
      f = g;
      if (done) break;
    }
    tops.emplace_back(f, c.w);
  }
  std::sort(tops.begin(), tops.end());
  std::vector<double> centres;
  for (std::size_t a = 0; a < tops.size();) {
    std::size_t b = a + 1;
    double sw = tops[a].second, swf = tops[a].second * tops[a].first;
    while (b < tops.size() && tops[b].first - tops[b - 1].first <= 0.25 * tol * tops[b - 1].first) sw += tops[b].second, swf += tops[b].second * tops[b].first, ++b;
    centres.push_back(sw > 0 ? swf / sw : tops[a].first);
    a = b;
  }
  return centres;
}

using Members = std::vector<std::vector<std::pair<double, std::size_t>>>;  // centre -> (weight, candidate)

// Each candidate supports the centre it is nearest to (relative distance).
Members centre_members(const std::vector<Cand>& cand, const std::vector<double>& centres, double tol) {
  const std::size_t nc = centres.size();
  Members members(nc);
  for (std::size_t a = 0; a < cand.size(); ++a) {
    const auto it = std::lower_bound(centres.begin(), centres.end(), cand[a].f);
    std::size_t c = static_cast<std::size_t>(it - centres.begin());
    if (c == nc || (c > 0 && std::abs(cand[a].f - centres[c - 1]) / centres[c - 1] < std::abs(centres[c] - cand[a].f) / centres[c])) --c;
    const double k = cand[a].w * window(std::abs(cand[a].f - centres[c]) / (tol * centres[c]));
    if (k > 0) members[c].emplace_back(k, a);
  }
  return members;
}

using OrderBest = std::map<int, std::pair<double, std::size_t>>;  // order -> (weight, candidate)

// Shape families within a centre: the poles of the two modes of a closely spaced pair share one window, and
// their vectors tell them apart. Strongest first, each pole joins the family whose mean vector it is most like,
// fully from a MAC of cluster_mac, with a share falling to 0 at 2 cluster_mac - 1 (below the middle it starts
// a family of its own). Scalar vectors (LSCF with one input) make one family. Per family and order the best
// pole counts.
std::vector<OrderBest> shape_families(Members members, const std::vector<Cand>& cand,
                                      const std::vector<std::vector<RawPole>>& orders, const IdentificationOptions& o) {
  const std::size_t nc = members.size();
  std::vector<OrderBest> best;  // per family
  for (std::size_t c = 0; c < nc; ++c) {
    std::stable_sort(members[c].begin(), members[c].end(),
                     [](const auto& x, const auto& y) { return x.first > y.first; });
    std::vector<Eigen::VectorXcd> mean;  // per family, the weighted sum of its aligned unit vectors
    const std::size_t first = best.size();
    for (const auto& [k, a] : members[c]) {
      const Eigen::VectorXcd& v0 = orders[static_cast<std::size_t>(cand[a].j)][static_cast<std::size_t>(cand[a].p)].vec;
      std::size_t f = 0;
      double like = 1;
      if (v0.size() > 1 && v0.norm() > 0) {
        Eigen::VectorXcd v = v0.normalized();
        double mac = -1;
        for (std::size_t q = 0; q < mean.size(); ++q) {
          const double m = complex_mac(v, mean[q]);
          if (m > mac) mac = m, f = q;
        }
        like = mac < 0 ? 0 : ramp((1 - mac) / std::max(1 - o.cluster_mac, 1e-12));
        if (like < 0.5) {
          f = mean.size(), like = 1;
          mean.push_back(Eigen::VectorXcd::Zero(v.size()));
          best.emplace_back();
        }
        const std::complex<double> d = mean[f].dot(v);  // conj(mean) . v
        if (std::abs(d) > 0) v *= std::conj(d) / std::abs(d);
        mean[f] += k * like * v;
      } else if (best.size() == first) {
        mean.emplace_back();
        best.emplace_back();
      }
      auto& slot = best[first + f][cand[a].j];
      if (k * like > slot.first) slot = {k * like, a};
    }
  }
  return best;
}

// A cluster of each family with poles at two orders or more: support, weighted frequency and damping and their
// spreads. Sorted by frequency.
std::vector<PoleCluster> clusters_of(const std::vector<OrderBest>& best, const std::vector<Cand>& cand, double n_orders,
                                     const IdentificationSummary& s) {
  std::vector<PoleCluster> out;
  for (std::size_t c = 0; c < best.size(); ++c) {
    if (best[c].size() < 2) continue;
    PoleCluster pc;
    double sw = 0, sf = 0, sz = 0;
    for (const auto& [ord, wk] : best[c]) {
      const Cand& q = cand[wk.second];
      pc.members.emplace_back(q.j, q.p);
      pc.member_weight.push_back(wk.first);
      pc.diagram_index.push_back(q.pole);
      sw += wk.first;
      sf += wk.first * q.f;
      sz += wk.first * s.poles[static_cast<std::size_t>(q.pole)].damping_ratio;
    }
    pc.support = sw / n_orders;
    pc.poles = static_cast<int>(best[c].size());
    pc.frequency_hz = sf / sw;
    pc.damping_ratio = sz / sw;
    double vf = 0, vz = 0;
    for (std::size_t m = 0; m < pc.members.size(); ++m) {
      const StabilizationPole& sp = s.poles[static_cast<std::size_t>(pc.diagram_index[m])];
      vf += pc.member_weight[m] * std::pow(sp.frequency_hz - pc.frequency_hz, 2);
      vz += pc.member_weight[m] * std::pow(sp.damping_ratio - pc.damping_ratio, 2);
    }
    pc.frequency_std_hz = std::sqrt(vf / sw);
    pc.damping_std = std::sqrt(vz / sw);
    out.push_back(std::move(pc));
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const PoleCluster& x, const PoleCluster& y) { return x.frequency_hz < y.frequency_hz; });
  return out;
}

}  // namespace

std::vector<PoleCluster> stabilize_and_cluster(const std::vector<std::vector<RawPole>>& orders,
                                               const std::vector<int>& order_of, double lo, double hi,
                                               const IdentificationOptions& o, IdentificationSummary& s) {
  const std::vector<Cand> cand = weighted_poles(orders, order_of, lo, hi, o, s);
  if (cand.empty()) return {};
  const std::vector<double> centres = density_centres(cand, o.cluster_tolerance);
  const auto families = shape_families(centre_members(cand, centres, o.cluster_tolerance), cand, orders, o);
  return clusters_of(families, cand, static_cast<double>(orders.size()), s);
}

namespace {
// The indicator in dB at x, linearly interpolated between lines (clamped to the lines' range).
double indicator_db(const Eigen::VectorXd& f, const Eigen::VectorXd& ind, double x) {
  const Eigen::Index n = f.size();
  const double df = (f[n - 1] - f[0]) / static_cast<double>(n - 1);
  const double pos = std::clamp((x - f[0]) / df, 0.0, static_cast<double>(n - 1));
  const Eigen::Index k = std::min<Eigen::Index>(static_cast<Eigen::Index>(pos), n - 2);
  const double t = pos - static_cast<double>(k);
  auto db = [&](Eigen::Index i) { return 10 * std::log10(std::max(ind[i], 1e-300)); };
  return (1 - t) * db(k) + t * db(k + 1);
}
}  // namespace

IndicatorEvidence indicator_evidence(const Eigen::VectorXd& f, const Eigen::VectorXd& ind, double fr, double zeta) {
  IndicatorEvidence e;
  const Eigen::Index n = f.size();
  if (n < 3 || ind.size() != n) return e;
  const double df = (f[n - 1] - f[0]) / static_cast<double>(n - 1);
  const double w = std::max(2 * zeta * fr, 2 * df);
  auto at = [&](double x) { return indicator_db(f, ind, x); };
  // The mode's level: the highest of its line neighbourhood (+- max(zeta f, df)).
  const double h = std::max(zeta * fr, df);
  double top = -1e300;
  for (int q = -4; q <= 4; ++q) top = std::max(top, at(fr + q * h / 4));
  const bool has_lo = fr - w >= f[0], has_hi = fr + w <= f[n - 1];
  if (has_lo && has_hi) e.peak_db = top - 0.5 * (at(fr - w) + at(fr + w));
  else if (has_lo) e.peak_db = top - at(fr - w);
  else if (has_hi) e.peak_db = top - at(fr + w);
  // The steepest fall either side beyond what the pole's own resonance allows at w: a power response falls by
  // 10 log10(1 + (w / (zeta f))^2) there (other modes and noise only fill it in).
  const double own = 10 * std::log10(1 + std::pow(w / std::max(zeta * fr, 1e-300), 2));
  if (has_lo) e.edge_db = std::max(e.edge_db, top - at(fr - w) - own);
  if (has_hi) e.edge_db = std::max(e.edge_db, top - at(fr + w) - own);
  return e;
}

double indicator_dip_db(const Eigen::VectorXd& f, const Eigen::VectorXd& ind, double fa, double fb, double smooth_hz) {
  const Eigen::Index n = f.size();
  if (n < 3 || ind.size() != n) return 0;
  if (fa > fb) std::swap(fa, fb);
  // The indicator in dB averaged over the lines within smooth_hz of x (the interpolated value where none is).
  auto level = [&](double x) {
    const Eigen::Index a = std::lower_bound(f.data(), f.data() + n, x - smooth_hz) - f.data();
    const Eigen::Index b = std::upper_bound(f.data(), f.data() + n, x + smooth_hz) - f.data();
    if (b <= a) return indicator_db(f, ind, x);
    double sum = 0;
    for (Eigen::Index k = a; k < b; ++k) sum += 10 * std::log10(std::max(ind[k], 1e-300));
    return sum / static_cast<double>(b - a);
  };
  const double top = std::min(level(fa), level(fb));
  double low = top;
  for (Eigen::Index k = 0; k < n; ++k)
    if (f[k] > fa && f[k] < fb) low = std::min(low, level(f[k]));
  return top - low;
}

bool is_split(const SplitSide& c, const SplitSide& h, double h_peak_db, const Eigen::VectorXd& frequency_hz,
              const Eigen::VectorXd& h_indicator, const IdentificationOptions& o) {
  const double tol = std::max(o.merge_tolerance, std::max(c.damping_ratio, h.damping_ratio));
  const double apart = std::abs(c.frequency_hz - h.frequency_hz);
  // Within the half-power window, or beyond it on the flank of the stronger one's indicator peak; never with a dip
  // of the indicator between them (two peaks: two modes, whose local shapes may look alike).
  if (apart > o.merge_span * h.frequency_hz) return false;
  if (apart > tol * h.frequency_hz && h_peak_db < o.min_peak_db) return false;
  const double smooth = 0.5 * std::min(c.damping_ratio * c.frequency_hz, h.damping_ratio * h.frequency_hz);
  if (indicator_dip_db(frequency_hz, h_indicator, c.frequency_hz, h.frequency_hz, smooth) >= o.min_peak_db)
    return false;
  return complex_mac(c.shape, h.shape) >= o.merge_mac;
}

namespace {
// Support of several clusters together: per order the best weight of any of them.
double joint_support(const std::vector<Candidate>& cands, const std::vector<std::size_t>& group, std::size_t n_orders) {
  std::map<int, double> best;
  for (std::size_t k : group) {
    const PoleCluster& c = cands[k].cluster;
    for (std::size_t m = 0; m < c.members.size(); ++m) {
      double& b = best[c.members[m].first];
      b = std::max(b, c.member_weight[m]);
    }
  }
  double sum = 0;
  for (const auto& [j, w] : best) sum += w;
  return sum / static_cast<double>(n_orders);
}
}  // namespace

namespace {
// The expected modes (IdentificationOptions::expected_modes) aligned to the outputs once: column k holds mode k's
// shape on the outputs it shares, `shared` marks them (1), 0 elsewhere.
class ExpectedAtOutputs {
 public:
  ExpectedAtOutputs(const IdentificationOptions& o, const std::vector<MeasuredDof>& outputs)
      : o_(o),
        shapes_(Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(outputs.size()),
                                      static_cast<Eigen::Index>(o.expected_modes.size()))),
        shared_(Eigen::MatrixXd::Zero(shapes_.rows(), shapes_.cols())) {
    for (Eigen::Index k = 0; k < shapes_.cols(); ++k) {
      const ExpectedMode& e = o.expected_modes[static_cast<std::size_t>(k)];
      for (Eigen::Index i = 0; i < shapes_.rows(); ++i)
        for (std::size_t j = 0; j < e.dofs.size(); ++j)
          if (e.dofs[j].node == outputs[static_cast<std::size_t>(i)].node &&
              e.dofs[j].dof == outputs[static_cast<std::size_t>(i)].dof) {
            shapes_(i, k) = e.shape[static_cast<Eigen::Index>(j)];
            shared_(i, k) = 1;
            break;
          }
    }
  }
  // The expected mode a mode of this frequency and (complex, at the outputs) shape matches: within expected_ratio in
  // frequency and of MAC >= expected_mac over at least 3 shared outputs (its shape taken real), the best by MAC;
  // -1 for none.
  int match(double f, const Eigen::VectorXcd& shape) const {
    if (shape.size() != shapes_.rows()) return -1;
    const Eigen::VectorXd x = real_normalize(shape);
    int best = -1;
    double best_mac = o_.expected_mac;
    for (Eigen::Index k = 0; k < shapes_.cols(); ++k) {
      const double r = f / o_.expected_modes[static_cast<std::size_t>(k)].frequency_hz;
      if (r > o_.expected_ratio || r < 1 / o_.expected_ratio || shared_.col(k).sum() < 3) continue;
      const double mac = mac_matrix(x.cwiseProduct(shared_.col(k)), shapes_.col(k))(0, 0);
      if (mac >= best_mac) best = static_cast<int>(k), best_mac = mac;
    }
    return best;
  }

 private:
  const IdentificationOptions& o_;
  Eigen::MatrixXd shapes_, shared_;
};
}  // namespace

std::vector<double> expected_frequencies(const IdentificationOptions& o, const IdentificationSummary& s) {
  std::vector<double> hz(s.modes.size(), 0.0);
  if (o.expected_modes.empty()) return hz;
  const ExpectedAtOutputs expected(o, s.dofs);
  for (std::size_t k = 0; k < s.modes.size(); ++k) {
    const int e = expected.match(s.modes[k].frequency_hz, s.modes[k].shape);
    if (e >= 0) hz[k] = o.expected_modes[static_cast<std::size_t>(e)].frequency_hz;
  }
  return hz;
}

std::vector<std::vector<std::size_t>> check_evidence(const std::vector<Candidate>& cands,
                                                     const std::vector<IndicatorEvidence>& ev,
                                                     const std::vector<Eigen::VectorXd>& indicators,
                                                     const IdentificationOptions& o, std::size_t n_orders,
                                                     IdentificationSummary& s) {
  auto reject = [&](const PoleCluster& c, Rejection r, double value, double limit, int into = -1) {
    RejectedCluster rc;
    rc.frequency_hz = c.frequency_hz;
    rc.damping_ratio = c.damping_ratio;
    rc.poles = c.poles;
    rc.support = c.support;
    rc.reason = r;
    rc.value = value;
    rc.limit = limit;
    rc.merged_into = into;
    s.rejected.push_back(rc);
  };
  // 1. Splits: clusters with a shape, strongest first; a weaker one within the merge window with the same shape
  //    joins the stronger (one physical mode whose poles drifted over the orders).
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < cands.size(); ++k) {
    if (cands[k].shape.size() > 0) order.push_back(k);
    else reject(cands[k].cluster, Rejection::kFewOrders, cands[k].cluster.support, o.min_cluster_fraction);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cands[a].strength > cands[b].strength; });
  std::vector<std::vector<std::size_t>> groups;
  std::vector<Eigen::VectorXcd> head_shape;
  for (std::size_t k : order) {
    const PoleCluster& c = cands[k].cluster;
    const Eigen::VectorXcd sk = real_normalize(cands[k].shape).cast<std::complex<double>>();
    int into = -1;
    for (std::size_t g = 0; g < groups.size() && into < 0; ++g) {
      const PoleCluster& h = cands[groups[g][0]].cluster;
      if (is_split({c.frequency_hz, c.damping_ratio, sk}, {h.frequency_hz, h.damping_ratio, head_shape[g]},
                   ev[groups[g][0]].peak_db, s.frequency_hz, indicators[groups[g][0]], o))
        into = static_cast<int>(g);
    }
    if (into < 0) {
      groups.push_back({k});
      head_shape.push_back(sk);
    } else {
      groups[static_cast<std::size_t>(into)].push_back(k);
    }
  }
  // 2. Support (of the group), MPC and the mode indicator (of its strongest cluster). A group short of support
  //    but shaped like a mode the model predicts (IdentificationOptions::expected_modes) is decided after the
  //    others, so that it never stands in for a mode they report.
  std::vector<std::vector<std::size_t>> kept;
  const ExpectedAtOutputs expected(o, s.dofs);
  struct Weak {
    const std::vector<std::size_t>* group;
    int expected;
    double support;
  };
  std::vector<Weak> weak;
  for (const std::vector<std::size_t>& g : groups) {
    const Candidate& h = cands[g[0]];
    const double support = joint_support(cands, g, n_orders);
    const double mpc = modal_phase_collinearity(h.shape);
    bool ok = false;
    if (support < o.min_cluster_fraction) {
      const int e = support >= o.expected_fraction ? expected.match(h.cluster.frequency_hz, h.shape) : -1;
      if (e >= 0) {
        weak.push_back({&g, e, support});
        continue;
      }
      for (std::size_t k : g) reject(cands[k].cluster, Rejection::kFewOrders, support, o.min_cluster_fraction);
    } else if (mpc < o.min_mpc) {
      for (std::size_t k : g) reject(cands[k].cluster, Rejection::kComplexShape, mpc, o.min_mpc);
    } else if (ev[g[0]].peak_db < o.min_peak_db) {
      for (std::size_t k : g) reject(cands[k].cluster, Rejection::kIndicatorTrough, ev[g[0]].peak_db, o.min_peak_db);
    } else if (ev[g[0]].edge_db > o.max_edge_db) {
      for (std::size_t k : g) reject(cands[k].cluster, Rejection::kSpectralEdge, ev[g[0]].edge_db, o.max_edge_db);
    } else {
      ok = true;
    }
    if (ok) kept.push_back(g);
  }
  // The model modes a reported mode already is (each reported mode matched once).
  std::vector<char> taken(o.expected_modes.size(), 0);
  for (const std::vector<std::size_t>& k : kept) {
    const int e = expected.match(cands[k[0]].cluster.frequency_hz, cands[k[0]].shape);
    if (e >= 0) taken[static_cast<std::size_t>(e)] = 1;
  }
  for (const Weak& w : weak) {
    const std::vector<std::size_t>& g = *w.group;
    const double mpc = modal_phase_collinearity(cands[g[0]].shape);
    if (taken[static_cast<std::size_t>(w.expected)] || mpc < o.min_mpc || ev[g[0]].peak_db < o.min_peak_db ||
        ev[g[0]].edge_db > o.max_edge_db) {
      for (std::size_t k : g) reject(cands[k].cluster, Rejection::kFewOrders, w.support, o.min_cluster_fraction);
      continue;
    }
    taken[static_cast<std::size_t>(w.expected)] = 1;
    kept.push_back(g);
  }
  // Ascending frequency (of the strongest cluster); the splits are listed against the mode they joined.
  std::sort(kept.begin(), kept.end(), [&](const auto& a, const auto& b) { return cands[a[0]].cluster.frequency_hz < cands[b[0]].cluster.frequency_hz; });
  for (std::size_t r = 0; r < kept.size(); ++r)
    for (std::size_t i = 1; i < kept[r].size(); ++i) {
      const std::size_t k = kept[r][i];
      const double mac = complex_mac(real_normalize(cands[k].shape).cast<std::complex<double>>(), real_normalize(cands[kept[r][0]].shape).cast<std::complex<double>>());
      reject(cands[k].cluster, Rejection::kSplit, mac, o.merge_mac, static_cast<int>(r));
    }
  std::sort(s.rejected.begin(), s.rejected.end(), [](const RejectedCluster& a, const RejectedCluster& b) { return a.frequency_hz < b.frequency_hz; });
  return kept;
}

void make_modes(const std::vector<Candidate>& cands, const std::vector<IndicatorEvidence>& ev,
                const std::vector<std::vector<std::size_t>>& accepted, std::size_t n_orders,
                const IdentificationOptions& o, IdentificationSummary& s) {
  s.modes.clear();
  const ExpectedAtOutputs expected(o, s.dofs);
  for (const std::vector<std::size_t>& g : accepted) {
    const Candidate& c = cands[g[0]];
    IdentifiedMode m;
    // Frequency, damping and their spreads are the strongest cluster's (a split's drifted poles would bias them).
    m.frequency_hz = c.cluster.frequency_hz;
    m.damping_ratio = c.cluster.damping_ratio;
    m.order_frequency_std_hz = m.frequency_std_hz = c.cluster.frequency_std_hz;
    m.damping_std = c.cluster.damping_std;
    m.indicator_db = ev[g[0]].peak_db;
    m.shape = c.shape;
    m.mpc = modal_phase_collinearity(c.shape);
    m.real_shape = real_normalize(c.shape);
    m.support = joint_support(cands, g, n_orders);
    if (m.support < o.min_cluster_fraction) {
      const int e = expected.match(m.frequency_hz, c.shape);
      if (e >= 0) m.expected_hz = o.expected_modes[static_cast<std::size_t>(e)].frequency_hz;
    }
    for (std::size_t k : g) {
      m.poles += cands[k].cluster.poles;
      for (int d : cands[k].cluster.diagram_index) s.poles[static_cast<std::size_t>(d)].cluster = static_cast<int>(s.modes.size());
    }
    s.modes.push_back(std::move(m));
  }
}

void select_modes(const OrderPoles& op, double lo, double hi, const IdentificationOptions& o,
                  const Eigen::VectorXd& indicator, double decay, const ShapeOf& shape_of,
                  const IndicatorOf& indicator_of, IdentificationSummary& s) {
  const std::vector<PoleCluster> clusters = stabilize_and_cluster(op.poles, op.order, lo, hi, o, s);
  std::vector<Candidate> cands(clusters.size());
  std::vector<IndicatorEvidence> peak(clusters.size());
  std::vector<Eigen::VectorXd> own(clusters.size());
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    cands[c].cluster = clusters[c];
    cands[c].strength = clusters[c].support;
    if (clusters[c].support >= kShapedShare * o.min_cluster_fraction) {
      const ClusterShape cs = shape_of(clusters, c);
      cands[c].shape = cs.shape;
      if (cs.strength >= 0) cands[c].strength = cs.strength;
      own[c] = indicator_of(cands[c].shape);
    } else {
      own[c] = indicator;
    }
    const double zw = clusters[c].damping_ratio + decay / (2 * M_PI * clusters[c].frequency_hz);
    peak[c] = indicator_evidence(s.frequency_hz, own[c], clusters[c].frequency_hz, zw);
  }
  make_modes(cands, peak, check_evidence(cands, peak, own, o, op.poles.size(), s), op.poles.size(), o, s);
}

}  // namespace dynid::internal

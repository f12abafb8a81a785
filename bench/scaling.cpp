// dynid_scaling -- the scaling driver: generated 2D frames up to 10^6 DOF and 3D space frames of ~5e4 and
// ~2.5e5 DOF; for each, the 20 lowest modes by dynid, and by SciPy's eigsh and SLEPc (Krylov-Schur,
// shift-and-invert, on CHOLMOD and on MUMPS) on the same matrices (Matrix Market), in the same run. Prints a table.
//
//   dynid_scaling [--quick] [--no-peers] [--only NAME] [--workdir DIR] [--peer-timeout S] [--ranks N]
//
// --ranks N: instead, the distributed backend (PETSc + SLEPc + MUMPS) under `mpiexec -n N` for each model, beside
// dynid's local solve: time, peak memory of every rank, MUMPS's factor entries, flops and memory, and the MPI traffic
// PETSc counted (what -log_view reports; MUMPS's own messages inside the factorization are not counted there).
//
// Each measurement runs in its own child process so that peak memory (ru_maxrss) is that run's alone.
#include <mpi.h>
#include <petsclog.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "blas_kernels.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/io/matrix_market.hpp"
#include "dynid/mesh/generators.hpp"
#include "dynid/solvers/blas.hpp"
#include "dynid/solvers/cholmod.hpp"
#include "dynid/solvers/distributed.hpp"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

namespace {

struct Spec {
  std::string name;
  bool three_d;
  int a, b, c, div;  // 2D: bays, stories, -, divisions; 3D: bays_x, bays_y, stories, divisions
};

dynid::Model Build(const Spec& s) {
  if (s.three_d) {
    dynid::Frame3DSpec f;
    f.bays_x = s.a;
    f.bays_y = s.b;
    f.stories = s.c;
    f.divisions = s.div;
    f.span_x = f.span_y = 6.0;
    f.height = 3.5;
    f.material = dynid::bench::Steel();
    f.column = dynid::bench::Column();
    f.beam = dynid::bench::Beam();
    return dynid::make_frame3d(f);
  }
  dynid::Frame2DSpec f;
  f.bays = s.a;
  f.stories = s.b;
  f.divisions = s.div;
  f.span = 6.0;
  f.height = 3.5;
  f.material = dynid::bench::Steel();
  f.column = dynid::bench::Column();
  f.beam = dynid::bench::Beam();
  return dynid::make_frame2d(f);
}

double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
double PeakMb() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

// Child: dynid's pipeline (assembly + eigen-solve of the 20 lowest modes) with timings.
int RunDynid(const Spec& s) {
  dynid::Model m = Build(s);
  const auto t0 = Clock::now();
  const dynid::AssembledSystem sys = dynid::assemble_system(m);
  dynid::EigenOptions o;
  o.num_modes = 20;
  o.method = dynid::EigenOptions::Method::kSparse;
  const dynid::ModalResult r = dynid::modal_analysis(m, sys, o);
  const double total = Since(t0);
  const double peak = PeakMb();
  // One more factorization to time a single solve pair (for the floor: factorization + solves).
  dynid::CholmodFactor F;
  F.analyze(sys.K);
  F.factorize(sys.K);
  Eigen::VectorXd b = Eigen::VectorXd::Ones(sys.K.rows()), x(sys.K.rows());
  const auto ts = Clock::now();
  for (int i = 0; i < 5; ++i) F.solve(b.data(), x.data());
  const double t_solve = Since(ts) / 5;
  json j = {{"dofs", r.dofs},
            {"nnz", r.nonzeros},
            {"assembly_s", r.time_assembly},
            {"analyze_s", r.summary.time_analyze},
            {"factorize_s", r.summary.time_factorize},
            {"lanczos_s", r.summary.time_lanczos},
            {"total_s", total},
            {"peak_rss_mb", peak},
            {"factor_nnz", r.summary.factor_nonzeros},
            {"factor_gflop", r.summary.factor_flops / 1e9},
            {"solves", r.summary.solves},
            {"solve_s", t_solve},
            {"status", r.ok() ? "ok" : r.summary.message},
            {"max_residual", r.summary.max_residual},
            {"eigenvalues", std::vector<double>(r.eigenvalues.data(), r.eigenvalues.data() + r.eigenvalues.size())}};
  std::cout << j.dump() << std::endl;
  return 0;
}

// Child under mpiexec: the distributed backend on every rank; rank 0 prints the JSON line with every rank's peak.
int RunDistributed(const Spec& s) {
  dynid::start_distributed_runtime();
  const int rank = dynid::distributed_rank(), size = dynid::distributed_size();
  dynid::Model m = Build(s);  // every rank holds the model's description; each assembles only its rows
  const double model_mb = PeakMb();
  MPI_Barrier(MPI_COMM_WORLD);
  const auto t0 = Clock::now();
  dynid::EigenOptions o;
  o.num_modes = 20;
  o.method = dynid::EigenOptions::Method::kSparse;
  o.backend = dynid::EigenOptions::Backend::kDistributed;
  const dynid::ModalResult r = dynid::modal_analysis(m, o);
  const double total = Since(t0);
  const double peak = PeakMb();
  std::vector<double> peaks(static_cast<std::size_t>(size)), models(static_cast<std::size_t>(size));
  MPI_Gather(&peak, 1, MPI_DOUBLE, peaks.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  MPI_Gather(&model_mb, 1, MPI_DOUBLE, models.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  double traffic[4] = {petsc_send_len + petsc_isend_len, petsc_send_ct + petsc_isend_ct, petsc_allreduce_ct, 0};
  double sum[4] = {0, 0, 0, 0};
  MPI_Reduce(traffic, sum, 4, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  if (rank != 0) return 0;
  json j = {{"dofs", r.dofs},
            {"nnz", r.nonzeros},
            {"ranks", size},
            {"assembly_s", r.time_assembly},
            {"factorize_s", r.summary.time_factorize},
            {"lanczos_s", r.summary.time_lanczos},
            {"total_s", total},
            {"peak_rss_mb_per_rank", peaks},
            {"model_rss_mb_per_rank", models},
            {"factor_entries", r.summary.factor_nonzeros},
            {"factor_gflop", r.summary.factor_flops / 1e9},
            {"mumps_mb_max_rank", r.summary.factor_memory_max_mb},
            {"mumps_mb_total", r.summary.factor_memory_total_mb},
            {"solves", r.summary.solves},
            {"petsc_sent_mb", sum[0] / 1048576.0},
            {"petsc_messages", sum[1]},
            {"petsc_allreduces", sum[2]},
            {"status", r.ok() ? "ok" : r.summary.message},
            {"max_residual", r.summary.max_residual},
            {"eigenvalues", std::vector<double>(r.eigenvalues.data(), r.eigenvalues.data() + r.eigenvalues.size())}};
  std::cout << j.dump() << std::endl;
  return 0;
}

int ExportMatrices(const Spec& s, const std::string& dir) {
  dynid::Model m = Build(s);
  const dynid::AssembledSystem sys = dynid::assemble_system(m);
  dynid::write_matrix_market(dir + "/K.mtx", sys.K, true, true);
  dynid::write_matrix_market(dir + "/M.mtx", sys.M, true, true);
  return 0;
}

// Runs a command, returns its stdout's last JSON line (or an error object), with a timeout.
json RunJson(const std::string& cmd, int timeout_s) {
  // Every child gets at most the machine's memory as address space: one that needs more (SuperLU on large 3D
  // models) fails by itself instead of the kernel's OOM killer choosing a process. (A fixed 20 GB stopped dynid's
  // 980,100-DOF 3D frame, 22 GB resident, on a 24 GiB machine.)
  const long kb = sysconf(_SC_PHYS_PAGES) / 1024 * sysconf(_SC_PAGE_SIZE);
  const std::string full =
      "ulimit -v " + std::to_string(kb) + "; timeout " + std::to_string(timeout_s) + " " + cmd + " 2>/dev/null";
  FILE* p = popen(full.c_str(), "r");
  if (!p) return json{{"error", "cannot start"}};
  std::string out, line;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) out += buf;
  const int rc = pclose(p);
  std::istringstream ss(out);
  json last;
  while (std::getline(ss, line))
    if (!line.empty() && line[0] == '{') last = json::parse(line, nullptr, false);
  if (last.is_null() || last.is_discarded()) {
    const int code = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    return json{{"error", code == 124 ? "timeout (" + std::to_string(timeout_s) + " s)" : "failed (exit " + std::to_string(code) + ")"}};
  }
  return last;
}

std::string Fmt(double v, const char* f = "%.2f") {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

double MaxRelDiff(const json& a, const json& b) {
  if (!a.contains("eigenvalues") || !b.contains("eigenvalues")) return NAN;
  const auto& x = a["eigenvalues"];
  const auto& y = b["eigenvalues"];
  double d = 0;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i)
    d = std::max(d, std::abs(x[i].get<double>() - y[i].get<double>()) / std::abs(y[i].get<double>()));
  return d;
}

// The distributed backend with `ranks` ranks beside dynid's local solve, one model at a time.
int DistributedTable(const std::vector<Spec>& specs, const std::string& only, const std::string& self, int ranks) {
  std::cout << "| model | DOF | ranks | local s | local peak MB | distributed s (factor / eigen) | peak MB per rank | "
               "factor entries (fill vs nnz(K)) | factor GFlop | MUMPS MB max rank / total | PETSc MPI MB (messages) | "
               "solves | max rel. diff of eigenvalues |\n"
            << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  const std::string mpi = std::string(DYNID_MPIEXEC) + " --allow-run-as-root --oversubscribe -n " +
                          std::to_string(ranks) + " -x OMP_NUM_THREADS=1 -x OPENBLAS_NUM_THREADS=1 ";
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const Spec& s = specs[k];
    if (!only.empty() && s.name.find(only) == std::string::npos) continue;
    const json d = RunJson(self + " --child " + std::to_string(k) + " run", 3600);
    const json p = RunJson(mpi + self + " --child " + std::to_string(k) + " mpi", 3600);
    if (p.contains("error")) {
      std::cout << "| " << s.name << " | local: " << d.value("error", "ok")
                << ", distributed: " << p.value("error", "ok") << " |" << std::endl;
      continue;
    }
    // A model too large for one process (the 10^6-DOF cubic frame) still gets its distributed row; the comparison
    // with the local eigenvalues is then left out, and the eigen-residuals stand for it.
    const bool local = !d.contains("error");
    std::string per_rank;
    for (const auto& v : p["peak_rss_mb_per_rank"])
      per_rank += (per_rank.empty() ? "" : " / ") + Fmt(v.get<double>(), "%.0f");
    const double fill = p["factor_entries"].get<double>() / p["nnz"].get<double>();
    std::cout << "| " << s.name << " | " << p["dofs"] << " | " << ranks << " | "
              << (local ? Fmt(d["total_s"]) : d.value("error", "")) << " | "
              << (local ? Fmt(d["peak_rss_mb"], "%.0f") : "-") << " | " << Fmt(p["total_s"]) << " ("
              << Fmt(p["factorize_s"]) << " / " << Fmt(p["lanczos_s"]) << ") | " << per_rank << " | "
              << Fmt(p["factor_entries"].get<double>(), "%.3g") << " (" << Fmt(fill, "%.1f") << ") | "
              << Fmt(p["factor_gflop"], "%.0f") << " | " << p["mumps_mb_max_rank"] << " / " << p["mumps_mb_total"]
              << " | " << Fmt(p["petsc_sent_mb"], "%.1f") << " (" << Fmt(p["petsc_messages"], "%.0f") << ") | "
              << p["solves"] << " | "
              << (local ? Fmt(MaxRelDiff(d, p), "%.1e")
                        : "- (largest eigen-residual " + Fmt(p["max_residual"], "%.1e") + ")")
              << " |" << std::endl;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  dynid::cli::ensure_blas_kernels(argv);  // children and peers inherit the same BLAS kernels
  std::vector<Spec> specs = {
      {"2D frame 10x10, div 10", false, 10, 10, 0, 10},
      {"2D frame 30x30, div 12", false, 30, 30, 0, 12},
      {"2D frame 100x100, div 17", false, 100, 100, 0, 17},
      {"3D frame 8x8x12, div 4", true, 8, 8, 12, 4},
      {"3D frame 20x20x20", true, 20, 20, 20, 1},
      {"3D frame 34x34x34", true, 34, 34, 34, 1},
      {"3D frame 14x14x20, div 4", true, 14, 14, 20, 4},
      {"3D frame 54x54x54", true, 54, 54, 54, 1},  // 980,100 DOF; 22 GB resident, ~10 min: run it alone (--only)
  };
  bool peers = true, quick = false;
  std::string only, workdir = (fs::temp_directory_path() / "dynid-scaling").string();
  int peer_timeout = 1800, ranks = 0;
  std::string self = argv[0];
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--no-peers") peers = false;
    else if (a == "--quick") quick = true;
    else if (a == "--only" && i + 1 < argc) only = argv[++i];
    else if (a == "--workdir" && i + 1 < argc) workdir = argv[++i];
    else if (a == "--peer-timeout" && i + 1 < argc) peer_timeout = std::atoi(argv[++i]);
    else if (a == "--ranks" && i + 1 < argc)
      ranks = std::atoi(argv[++i]);
    else if (a == "--child" && i + 2 < argc) {  // internal: --child INDEX run|export [dir]
      const Spec& s = specs.at(static_cast<std::size_t>(std::atoi(argv[++i])));
      const std::string what = argv[++i];
      if (what == "run") return RunDynid(s);
      if (what == "mpi") return RunDistributed(s);
      return ExportMatrices(s, argv[++i]);
    } else {
      std::cerr << "usage: dynid_scaling [--quick] [--no-peers] [--only NAME-SUBSTRING] [--workdir DIR] "
                   "[--peer-timeout S] [--ranks N]\n";
      return 2;
    }
  }
  if (quick) specs.resize(1), specs[0] = {"2D frame 10x10, div 10", false, 10, 10, 0, 10};
  fs::create_directories(workdir);
  const std::string py = "/usr/bin/python3 " + (fs::path(DYNID_BENCH_DIR) / "peers.py").string();
  {
    std::ifstream cpu("/proc/cpuinfo");
    std::string line, model;
    while (std::getline(cpu, line))
      if (line.rfind("model name", 0) == 0) {
        model = line.substr(line.find(':') + 2);
        break;
      }
    std::cout << "Machine: " << model << ", " << sysconf(_SC_NPROCESSORS_ONLN) << " cores, BLAS: "
              << dynid::blas_description() << ". 20 lowest modes, shift 0, tolerance 1e-10 for all solvers.\n\n";
  }
  if (ranks > 0) return DistributedTable(specs, only, self, ranks);
  std::cout << "| model | DOF | nnz(K) | assembly s | factorize s | eigen-solve s | total s | peak MB | solves | floor "
               "s | total/floor | SciPy s (ratio) | SciPy MB | SLEPc + CHOLMOD s (ratio) | MB | SLEPc + MUMPS s "
               "(ratio) | MB | max rel. diff of eigenvalues |\n"
            << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const Spec& s = specs[k];
    if (!only.empty() && s.name.find(only) == std::string::npos) continue;
    const json d = RunJson(self + " --child " + std::to_string(k) + " run", 3600);
    if (d.contains("error")) {
      std::cout << "| " << s.name << " | dynid " << d["error"].get<std::string>() << " |\n";
      continue;
    }
    json sp, sl, sm;
    if (peers) {
      const std::string dir = workdir + "/" + std::to_string(k);
      fs::create_directories(dir);
      RunJson(self + " --child " + std::to_string(k) + " export " + dir, 3600);
      const std::string files = dir + "/K.mtx " + dir + "/M.mtx --nev 20 --sigma 0";
      sl = RunJson(py + " slepc " + files, peer_timeout);
      sm = RunJson(py + " slepc-mumps " + files, peer_timeout);
      sp = RunJson(py + " scipy " + files, peer_timeout);
      fs::remove_all(dir);
    }
    const double total = d["total_s"], floor = d["factorize_s"].get<double>() + d["solves"].get<int>() * d["solve_s"].get<double>();
    auto peer = [&](const json& p) -> std::string {
      if (!peers) return "- | -";
      if (p.contains("error")) return p["error"].get<std::string>() + " | -";
      return Fmt(p["time_s"]) + " (" + Fmt(p["time_s"].get<double>() / total, "%.1fx") + ") | " + Fmt(p["peak_rss_mb"], "%.0f");
    };
    double diff = NAN;  // the largest over the peers that returned eigenvalues
    if (peers)
      for (const json* p : {&sl, &sm, &sp})
        if (const double x = MaxRelDiff(d, *p); !std::isnan(x)) diff = std::isnan(diff) ? x : std::max(diff, x);
    std::cout << "| " << s.name << " | " << d["dofs"] << " | " << d["nnz"] << " | " << Fmt(d["assembly_s"]) << " | "
              << Fmt(d["analyze_s"].get<double>() + d["factorize_s"].get<double>()) << " | " << Fmt(d["lanczos_s"])
              << " | " << Fmt(total) << " | " << Fmt(d["peak_rss_mb"], "%.0f") << " | " << d["solves"] << " | "
              << Fmt(floor) << " | " << Fmt(total / floor, "%.2f") << " | " << peer(sp) << " | " << peer(sl) << " | "
              << peer(sm) << " | " << (std::isnan(diff) ? std::string("-") : Fmt(diff, "%.1e")) << " |" << std::endl;
  }
  return 0;
}

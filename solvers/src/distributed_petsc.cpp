// The distributed backend's MPI, PETSc and SLEPc work (solvers/distributed.hpp, docs/distributed.md), built as the
// plugin libdynid_distributed.so that src/distributed.cpp loads on first use. It links no dynid library: the
// assembler, the modes' conventions and the METIS partition come from dynid_solvers through DistributedHost
// (internal/distributed_backend.hpp). Its one exported symbol is dynid_distributed_backend.
#include <petscksp.h>
#include <slepceps.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>

#include "dynid/mesh/error.hpp"
#include "internal/distributed_backend.hpp"

static_assert(sizeof(PetscInt) == sizeof(int), "dynid's distributed backend is built for 32-bit PetscInt");
static_assert(sizeof(PetscScalar) == sizeof(double), "dynid's distributed backend needs real double PETSc");

namespace dynid {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A PETSc or SLEPc call that returned an error: what it was and PETSc's text for the code.
struct PetscFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void check(PetscErrorCode code, const char* what) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw PetscFailure(std::string(what) + ": " + (text ? text : "PETSc error") + " (code " + std::to_string(code) + ")");
}
#define DYNID_PETSC(call) check((call), #call)

// Finalizes SLEPc and PETSc (and MPI, if PETSc started it) at process exit.
struct RuntimeGuard {
  bool started = false;
  ~RuntimeGuard() {
    if (started) SlepcFinalize();
  }
};

// Starts MPI (unless the program did), PETSc and SLEPc once per process (start_distributed_runtime).
void start_runtime() {
  static std::mutex mu;
  static RuntimeGuard guard;
  std::lock_guard<std::mutex> lock(mu);
  PetscBool up = PETSC_FALSE;
  SlepcInitialized(&up);
  if (up) return;
  // No command line: PETSc options come from PETSC_OPTIONS, so that they never clash with a program's own.
  if (SlepcInitializeNoArguments() != 0) throw InternalError("could not start MPI, PETSc and SLEPc");
  guard.started = true;
  // PETSc errors come back as codes (turned into EigenSummary failures), not as tracebacks on stderr.
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
}

int world_rank() {
  start_runtime();
  int r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}

int world_size() {
  start_runtime();
  int s = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  return s;
}

// Owned PETSc objects (destroyed in reverse order of creation by their holders): h, destroyed with Destroy.
template <class T, PetscErrorCode (*Destroy)(T*)>
struct Owned {
  Owned() = default;
  Owned(const Owned&) = delete;
  Owned& operator=(const Owned&) = delete;
  ~Owned() { Destroy(&h); }
  T h = nullptr;
};
using OwnedMat = Owned<Mat, MatDestroy>;
using OwnedVec = Owned<Vec, VecDestroy>;
using OwnedEps = Owned<EPS, EPSDestroy>;
// A scatter to all ranks and the vector it fills (the scatter destroyed first).
struct OwnedScatter {
  OwnedVec all;
  Owned<VecScatter, VecScatterDestroy> s;
};

// This rank's rows of K and M in the distributed numbering (rows [begin, end) of n; column indices global in the
// same numbering), and the numbering itself (new_of_old, replicated).
struct LocalSystem {
  int n = 0, begin = 0, end = 0;
  std::vector<int> new_of_old, old_of_new;
  std::vector<PetscInt> ptr, col;
  std::vector<double> k, m;
  double time_assembly = 0;
};

// The elements of `source` touching a set of DOFs, renumbered: the share of one rank.
class RankShare : public ElementSource {
 public:
  RankShare(const ElementSource& s, std::vector<int> elements, const std::vector<int>& new_of_old)
      : s_(s), elements_(std::move(elements)), map_(new_of_old) {}
  int num_dofs() const override { return s_.num_dofs(); }
  int num_elements() const override { return static_cast<int>(elements_.size()); }
  void element_dofs(int e, std::vector<int>* dofs) const override {
    s_.element_dofs(elements_[static_cast<std::size_t>(e)], dofs);
    for (int& d : *dofs)
      if (d >= 0) d = map_[static_cast<std::size_t>(d)];
  }
  void element_matrices(int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const override {
    s_.element_matrices(elements_[static_cast<std::size_t>(e)], K, M);
  }

 private:
  const ElementSource& s_;
  std::vector<int> elements_;
  const std::vector<int>& map_;
};

// Rows [b, e) of symmetric matrices stored in full (CSC): column j = row j, so the rows are the columns.
void take_rows(const SparseMatrix& K, const SparseMatrix& M, int b, int e, LocalSystem* ls) {
  const int* cp = K.outerIndexPtr();
  const int p0 = cp[b], p1 = cp[e];
  ls->ptr.resize(static_cast<std::size_t>(e - b + 1));
  for (int i = b; i <= e; ++i) ls->ptr[static_cast<std::size_t>(i - b)] = cp[i] - p0;
  ls->col.assign(K.innerIndexPtr() + p0, K.innerIndexPtr() + p1);
  ls->k.assign(K.valuePtr() + p0, K.valuePtr() + p1);
  ls->m.assign(M.valuePtr() + p0, M.valuePtr() + p1);
}

LocalSystem assemble_local(const detail::DistributedHost& host, const ElementSource& src, int size, int rank) {
  const auto t0 = Clock::now();
  LocalSystem ls;
  ls.n = src.num_dofs();
  std::vector<int> part(static_cast<std::size_t>(ls.n), 0);
  if (size > 1) {
    if (rank == 0) part = host.partition(src, size);
    MPI_Bcast(part.data(), ls.n, MPI_INT, 0, PETSC_COMM_WORLD);
  }
  // New numbering: the parts one after the other, each in the original order.
  std::vector<int> first(static_cast<std::size_t>(size) + 1, 0);
  for (int p : part) ++first[static_cast<std::size_t>(p) + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  ls.begin = first[static_cast<std::size_t>(rank)];
  ls.end = first[static_cast<std::size_t>(rank) + 1];
  ls.new_of_old.resize(static_cast<std::size_t>(ls.n));
  ls.old_of_new.resize(static_cast<std::size_t>(ls.n));
  for (int i = 0; i < ls.n; ++i) {
    const int j = first[static_cast<std::size_t>(part[static_cast<std::size_t>(i)])]++;
    ls.new_of_old[static_cast<std::size_t>(i)] = j;
    ls.old_of_new[static_cast<std::size_t>(j)] = i;
  }
  // This rank's elements: those with a DOF in its rows. Only they are evaluated here.
  std::vector<int> mine, dofs;
  for (int e = 0; e < src.num_elements(); ++e) {
    src.element_dofs(e, &dofs);
    for (int d : dofs)
      if (d >= 0 && part[static_cast<std::size_t>(d)] == rank) {
        mine.push_back(e);
        break;
      }
  }
  const RankShare share(src, std::move(mine), ls.new_of_old);
  SparseMatrix K, M;
  host.assemble(share, &K, &M);
  take_rows(K, M, ls.begin, ls.end, &ls);
  ls.time_assembly = seconds_since(t0);
  return ls;
}

Mat make_mat(const LocalSystem& ls, const std::vector<double>& values) {
  Mat A = nullptr;
  DYNID_PETSC(MatCreateMPIAIJWithArrays(PETSC_COMM_WORLD, ls.end - ls.begin, ls.end - ls.begin, ls.n, ls.n,
                                        ls.ptr.data(), ls.col.data(), values.data(), &A));
  DYNID_PETSC(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE));
  DYNID_PETSC(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  return A;
}

// The local rows of an n-vector in the original numbering (replicated), as a PETSc vector.
void fill_local(const LocalSystem& ls, const double* x_old, Vec v) {
  PetscScalar* a = nullptr;
  DYNID_PETSC(VecGetArray(v, &a));
  for (int i = ls.begin; i < ls.end; ++i) a[i - ls.begin] = x_old[ls.old_of_new[static_cast<std::size_t>(i)]];
  DYNID_PETSC(VecRestoreArray(v, &a));
}

// The whole vector v on every rank, in the original numbering.
void gather(const LocalSystem& ls, Vec v, OwnedScatter* sc, double* x_old) {
  if (!sc->s.h) DYNID_PETSC(VecScatterCreateToAll(v, &sc->s.h, &sc->all.h));
  DYNID_PETSC(VecScatterBegin(sc->s.h, v, sc->all.h, INSERT_VALUES, SCATTER_FORWARD));
  DYNID_PETSC(VecScatterEnd(sc->s.h, v, sc->all.h, INSERT_VALUES, SCATTER_FORWARD));
  const PetscScalar* a = nullptr;
  DYNID_PETSC(VecGetArrayRead(sc->all.h, &a));
  for (int i = 0; i < ls.n; ++i) x_old[i] = a[ls.new_of_old[static_cast<std::size_t>(i)]];
  DYNID_PETSC(VecRestoreArrayRead(sc->all.h, &a));
}

// The shift scale s0 = sqrt(eps) max_i K_ii / M_ii over all ranks (solve_eigen's free-free shift).
double shift_scale(const LocalSystem& ls) {
  const int rows = ls.end - ls.begin;
  Eigen::VectorXd kd = Eigen::VectorXd::Zero(rows), md = Eigen::VectorXd::Zero(rows);
  for (int i = 0; i < rows; ++i)
    for (PetscInt p = ls.ptr[static_cast<std::size_t>(i)]; p < ls.ptr[static_cast<std::size_t>(i) + 1]; ++p)
      if (ls.col[static_cast<std::size_t>(p)] == ls.begin + i) {
        kd[i] = ls.k[static_cast<std::size_t>(p)];
        md[i] = ls.m[static_cast<std::size_t>(p)];
      }
  // The same reduction as the local path: the ratio where M_ii > 0, else the largest |K_ii|.
  double ratio = 0, kmax = 0;
  for (int i = 0; i < rows; ++i) {
    if (md[i] > 0) ratio = std::max(ratio, std::abs(kd[i]) / md[i]);
    kmax = std::max(kmax, std::abs(kd[i]));
  }
  double local[2] = {ratio, kmax}, global[2] = {0, 0};
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  const double r = global[0] > 0 ? global[0] : (global[1] > 0 ? global[1] : 1.0);
  return std::sqrt(std::numeric_limits<double>::epsilon()) * r;
}

void set_option_unless_given(const char* name, const char* value) {
  PetscBool given = PETSC_FALSE;
  PetscOptionsHasName(nullptr, nullptr, name, &given);
  if (!given) PetscOptionsSetValue(nullptr, name, value);
}

// One Krylov-Schur run at shift sigma. Returns false (and fills the summary) if the factorization failed.
struct EpsRun {
  OwnedEps eps;
  bool factor_ok = true;
  std::string why;
};

void configure(EPS eps, Mat K, Mat M, const EigenOptions& opt, int nev, double sigma) {
  DYNID_PETSC(EPSSetOperators(eps, K, M));
  DYNID_PETSC(EPSSetProblemType(eps, EPS_GHEP));
  DYNID_PETSC(EPSSetType(eps, EPSKRYLOVSCHUR));
  DYNID_PETSC(EPSSetDimensions(eps, nev, opt.subspace > 0 ? opt.subspace : PETSC_DEFAULT, PETSC_DEFAULT));
  DYNID_PETSC(EPSSetTolerances(eps, opt.tolerance, opt.max_restarts));
  DYNID_PETSC(EPSSetTarget(eps, sigma));
  DYNID_PETSC(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  ST st = nullptr;
  DYNID_PETSC(EPSGetST(eps, &st));
  DYNID_PETSC(STSetType(st, STSINVERT));
  DYNID_PETSC(STSetMatStructure(st, SAME_NONZERO_PATTERN));
  KSP ksp = nullptr;
  PC pc = nullptr;
  DYNID_PETSC(STGetKSP(st, &ksp));
  DYNID_PETSC(KSPGetPC(ksp, &pc));
  if (opt.distributed_solver == EigenOptions::DistributedSolver::kMumpsCholesky) {
    DYNID_PETSC(KSPSetType(ksp, KSPPREONLY));
    DYNID_PETSC(PCSetType(pc, PCCHOLESKY));
    DYNID_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    // MUMPS's null-pivot detection, so that a singular K - sigma M is reported (INFOG(28)) rather than solved.
    set_option_unless_given("-st_mat_mumps_icntl_24", "1");
  } else {
    DYNID_PETSC(KSPSetType(ksp, KSPCG));
    DYNID_PETSC(PCSetType(pc, PCHYPRE));
    DYNID_PETSC(KSPSetTolerances(ksp, opt.iterative_tolerance, PETSC_DEFAULT, PETSC_DEFAULT, 10000));
  }
  DYNID_PETSC(EPSSetFromOptions(eps));
}

// MUMPS's statistics of the factorization in `eps` (MUMPS only); false with a reason if it failed or K - sigma M
// is not positive definite (negative or null pivots).
bool factor_statistics(EPS eps, EigenSummary* sum, std::string* why) {
  ST st = nullptr;
  KSP ksp = nullptr;
  PC pc = nullptr;
  Mat F = nullptr;
  DYNID_PETSC(EPSGetST(eps, &st));
  DYNID_PETSC(STGetKSP(st, &ksp));
  DYNID_PETSC(KSPGetPC(ksp, &pc));
  PCFailedReason reason = PC_NOERROR;
  DYNID_PETSC(PCGetFailedReason(pc, &reason));
  DYNID_PETSC(PCFactorGetMatrix(pc, &F));
  PetscInt info1 = 0, neg = 0, null = 0, entries = 0, mem_max = 0, mem_total = 0;
  PetscReal flops = 0;
  DYNID_PETSC(MatMumpsGetInfog(F, 1, &info1));
  DYNID_PETSC(MatMumpsGetInfog(F, 12, &neg));
  DYNID_PETSC(MatMumpsGetInfog(F, 28, &null));
  DYNID_PETSC(MatMumpsGetInfog(F, 29, &entries));
  DYNID_PETSC(MatMumpsGetInfog(F, 21, &mem_max));
  DYNID_PETSC(MatMumpsGetInfog(F, 22, &mem_total));
  DYNID_PETSC(MatMumpsGetRinfog(F, 3, &flops));
  sum->factor_nonzeros = entries >= 0 ? entries : -static_cast<long long>(entries) * 1000000LL;
  sum->factor_flops = flops;
  sum->factor_memory_max_mb = static_cast<double>(mem_max);
  sum->factor_memory_total_mb = static_cast<double>(mem_total);
  if (info1 < 0 || reason != PC_NOERROR) {
    *why = "MUMPS factorization of K - sigma M failed (INFOG(1) = " + std::to_string(info1) + ")";
    return false;
  }
  if (null > 0 || neg > 0) {
    *why = "K - sigma M is not positive definite (MUMPS: " + std::to_string(neg) + " negative and " +
           std::to_string(null) + " null pivots)";
    return false;
  }
  return true;
}

Eigen::VectorXd to_vector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

EigenSolution solve_local_system(const detail::DistributedHost& host, const LocalSystem& ls, const EigenOptions& opt) {
  EigenSolution sol;
  EigenSummary& sum = sol.summary;
  sum.ranks = world_size();
  sum.time_assembly = ls.time_assembly;
  const bool mumps = opt.distributed_solver == EigenOptions::DistributedSolver::kMumpsCholesky;
  sum.method = std::string("distributed shift-and-invert Krylov-Schur (SLEPc, ") +
               (mumps ? "MUMPS Cholesky" : "CG + BoomerAMG") + ", " + std::to_string(sum.ranks) + " ranks)";
  const int n = ls.n;
  OwnedMat K, M;
  K.h = make_mat(ls, ls.k);
  M.h = make_mat(ls, ls.m);
  MatInfo info;
  DYNID_PETSC(MatGetInfo(K.h, MAT_GLOBAL_SUM, &info));
  sum.matrix_nonzeros = static_cast<long long>(info.nz_used);
  PetscReal nK = 0, nM = 0;
  DYNID_PETSC(MatNorm(K.h, NORM_1, &nK));
  DYNID_PETSC(MatNorm(M.h, NORM_1, &nM));
  OwnedVec x, kx, mx;
  DYNID_PETSC(MatCreateVecs(K.h, &x.h, &kx.h));
  DYNID_PETSC(VecDuplicate(x.h, &mx.h));

  // Rigid-body modes from the basis: M-orthonormalised (B^T M B from distributed products), exact, deflated.
  const Eigen::Index r = opt.rigid_body_basis.cols();
  Eigen::MatrixXd Phi(n, 0);
  std::vector<OwnedVec> defl(static_cast<std::size_t>(r));
  if (r > 0) {
    Eigen::MatrixXd G(r, r);
    for (Eigen::Index j = 0; j < r; ++j) DYNID_PETSC(VecDuplicate(x.h, &defl[static_cast<std::size_t>(j)].h));
    for (Eigen::Index j = 0; j < r; ++j) {
      fill_local(ls, opt.rigid_body_basis.col(j).data(), defl[static_cast<std::size_t>(j)].h);
      DYNID_PETSC(MatMult(M.h, defl[static_cast<std::size_t>(j)].h, mx.h));
      for (Eigen::Index i = 0; i < r; ++i) {
        if (i > j) continue;
        fill_local(ls, opt.rigid_body_basis.col(i).data(), x.h);
        PetscScalar d = 0;
        DYNID_PETSC(VecDot(mx.h, x.h, &d));
        G(i, j) = G(j, i) = d;
      }
    }
    // Phi = B L^{-T} with G = L L^T, as detail::m_orthonormalize does with MB; here G itself is what is known.
    const Eigen::LLT<Eigen::MatrixXd> llt(G);
    if (llt.info() != Eigen::Success)
      throw InputError("rigid-body basis: the rigid-body motions have no mass (B^T M B is not positive definite)");
    Phi = llt.matrixL().solve(opt.rigid_body_basis.transpose()).transpose();
    for (Eigen::Index j = 0; j < r; ++j) fill_local(ls, Phi.col(j).data(), defl[static_cast<std::size_t>(j)].h);
  }
  const double s0 = shift_scale(ls);
  const int nev = opt.num_modes - static_cast<int>(r);
  double sigma = !std::isnan(opt.shift) ? opt.shift : (r > 0 ? -s0 : 0.0);
  sum.num_rigid = static_cast<int>(r);

  std::vector<double> lam;
  std::vector<char> rigid;
  Eigen::MatrixXd modes(n, 0);
  const int rigid_take = std::min<int>(static_cast<int>(r), opt.num_modes);
  for (int j = 0; j < rigid_take; ++j) {
    DYNID_PETSC(MatMult(K.h, defl[static_cast<std::size_t>(j)].h, kx.h));
    PetscScalar d = 0;
    DYNID_PETSC(VecDot(kx.h, defl[static_cast<std::size_t>(j)].h, &d));
    lam.push_back(d);
    rigid.push_back(1);
  }
  bool converged = true;
  OwnedScatter scatter;
  if (nev > 0) {
    if (nev > n - r - 1) {
      sum.status = EigenStatus::kInvalidInput;
      sum.message = "too many modes requested for the distributed solver (" + std::to_string(opt.num_modes) + " of " +
                    std::to_string(n) + " DOFs)";
      return sol;
    }
    EpsRun run;
    auto set_up = [&](double s) {
      EPSDestroy(&run.eps.h);
      DYNID_PETSC(EPSCreate(PETSC_COMM_WORLD, &run.eps.h));
      configure(run.eps.h, K.h, M.h, opt, nev, s);
      if (r > 0) {
        std::vector<Vec> vs;
        for (auto& v : defl) vs.push_back(v.h);
        DYNID_PETSC(EPSSetDeflationSpace(run.eps.h, static_cast<PetscInt>(r), vs.data()));
      }
      const auto tf = Clock::now();
      if (opt.progress) opt.progress("factorize", -1);
      const PetscErrorCode code = EPSSetUp(run.eps.h);
      sum.time_factorize += seconds_since(tf);
      run.why.clear();
      run.factor_ok = code == 0 && (!mumps || factor_statistics(run.eps.h, &sum, &run.why));
      if (code != 0) {
        const char* text = nullptr;
        PetscErrorMessage(code, &text, nullptr);
        run.why = std::string("setting up the shift-and-invert solve failed: ") + (text ? text : "PETSc error");
      }
      return run.factor_ok;
    };
    bool ok = set_up(sigma);
    if (!ok && std::isnan(opt.shift) && sigma == 0.0 && opt.allow_singular_stiffness) ok = set_up(sigma = -s0);
    sum.shift = sigma;
    if (!ok) {
      sum.status = EigenStatus::kFactorizationFailed;
      sum.message = sigma == 0.0 ? "K is singular or not positive definite: the structure is a mechanism or is not "
                                   "supported (" +
                                       run.why + ")"
                                 : run.why;
      return sol;
    }
    const auto tl = Clock::now();
    if (opt.progress) opt.progress("lanczos", -1);
    const PetscErrorCode code = EPSSolve(run.eps.h);
    sum.time_lanczos = seconds_since(tl);
    if (code != 0) {
      const char* text = nullptr;
      PetscErrorMessage(code, &text, nullptr);
      sum.status = EigenStatus::kNotConverged;
      sum.message = std::string("SLEPc's solve failed: ") + (text ? text : "PETSc error");
      return sol;
    }
    PetscInt nconv = 0, its = 0, solves = 0;
    DYNID_PETSC(EPSGetConverged(run.eps.h, &nconv));
    DYNID_PETSC(EPSGetIterationNumber(run.eps.h, &its));
    ST st = nullptr;
    KSP ksp = nullptr;
    DYNID_PETSC(EPSGetST(run.eps.h, &st));
    DYNID_PETSC(STGetKSP(st, &ksp));
    DYNID_PETSC(KSPGetTotalIterations(ksp, &solves));
    sum.restarts = static_cast<int>(its);
    sum.solves = static_cast<int>(solves);  // MUMPS: one per solve; CG: the total CG iterations
    const int take = static_cast<int>(std::min<PetscInt>(nconv, nev));
    if (take < nev) {
      converged = false;
      sum.message = "Krylov-Schur converged " + std::to_string(take) + " of " + std::to_string(nev) + " modes in " +
                    std::to_string(opt.max_restarts) + " restarts; raise max_restarts or the subspace size";
    }
    modes.resize(n, rigid_take + take);
    std::vector<double> buf(static_cast<std::size_t>(n));
    for (int k = 0; k < take; ++k) {
      PetscScalar l = 0;
      DYNID_PETSC(EPSGetEigenpair(run.eps.h, k, &l, nullptr, x.h, nullptr));
      DYNID_PETSC(MatMult(M.h, x.h, mx.h));
      PetscScalar xmx = 0;
      DYNID_PETSC(VecDot(x.h, mx.h, &xmx));
      DYNID_PETSC(VecScale(x.h, 1.0 / std::sqrt(xmx)));  // mass-normalised
      gather(ls, x.h, &scatter, buf.data());
      modes.col(rigid_take + k) = to_vector(buf);
      lam.push_back(l);
      rigid.push_back(0);
    }
  }
  modes.leftCols(rigid_take) = Phi.leftCols(rigid_take);
  sol.eigenvalues = Eigen::Map<Eigen::VectorXd>(lam.data(), static_cast<Eigen::Index>(lam.size()));
  sol.modes = std::move(modes);
  sol.rigid_body = rigid;
  host.finish(&sol);

  // Residuals (and, without a rigid basis below a negative shift, zero-energy modes recognised as rigid).
  const Eigen::Index m = sol.eigenvalues.size();
  sol.residuals.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    fill_local(ls, sol.modes.col(k).data(), x.h);
    DYNID_PETSC(MatMult(K.h, x.h, kx.h));
    DYNID_PETSC(MatMult(M.h, x.h, mx.h));
    PetscReal nx = 0, nr = 0;
    DYNID_PETSC(VecNorm(x.h, NORM_2, &nx));
    DYNID_PETSC(VecAXPY(kx.h, -sol.eigenvalues[k], mx.h));
    DYNID_PETSC(VecNorm(kx.h, NORM_2, &nr));
    sol.residuals[k] = nr / ((nK + std::abs(sol.eigenvalues[k]) * nM) * nx);
    // s0 / sqrt(eps) = max_i K_ii / M_ii: the eigenvalue test of EigenOptions::rigid_eigenvalue_tolerance.
    if (r == 0 && sigma < 0 && opt.allow_singular_stiffness &&
        sol.eigenvalues[k] <= opt.rigid_eigenvalue_tolerance * s0 / std::sqrt(std::numeric_limits<double>::epsilon()))
      sol.rigid_body[k] = 1;
  }
  if (r == 0) sum.num_rigid = static_cast<int>(std::count(sol.rigid_body.begin(), sol.rigid_body.end(), 1));
  sum.max_residual = m > 0 ? sol.residuals.maxCoeff() : 0.0;
  sum.status = converged ? EigenStatus::kSuccess : EigenStatus::kNotConverged;
  if (opt.progress) opt.progress("done", 1.0);
  return sol;
}

// Runs `body`, turning a PETSc error into a failed summary (an InputError passes through).
EigenSolution guarded(const std::function<EigenSolution()>& body) {
  try {
    return body();
  } catch (const PetscFailure& e) {
    EigenSolution s;
    s.summary.status = EigenStatus::kNotConverged;
    s.summary.method = "distributed shift-and-invert Krylov-Schur (SLEPc)";
    s.summary.message = std::string("PETSc/SLEPc error: ") + e.what();
    return s;
  }
}

EigenSolution solve_elements(const detail::DistributedHost& host, const ElementSource& source,
                             const EigenOptions& options) {
  start_runtime();
  const int ranks = world_size(), me = world_rank();
  return guarded([&] { return solve_local_system(host, assemble_local(host, source, ranks, me), options); });
}

EigenSolution solve_matrices(const detail::DistributedHost& host, const SparseMatrix& K, const SparseMatrix& M,
                             const EigenOptions& options) {
  start_runtime();
  const int ranks = world_size(), me = world_rank();
  return guarded([&] {
    const auto t0 = Clock::now();
    LocalSystem ls;
    ls.n = static_cast<int>(K.rows());
    detail::split_evenly(ls.n, ranks, me, &ls.begin, &ls.end);
    ls.new_of_old.resize(static_cast<std::size_t>(ls.n));
    std::iota(ls.new_of_old.begin(), ls.new_of_old.end(), 0);
    ls.old_of_new = ls.new_of_old;
    // K and M on their union pattern (as the local path does), so that K - sigma M keeps it.
    const SparseMatrix P = K.cwiseAbs() + M.cwiseAbs();
    SparseMatrix Ku = P * 0.0 + K, Mu = P * 0.0 + M;
    Ku.makeCompressed();
    Mu.makeCompressed();
    take_rows(Ku, Mu, ls.begin, ls.end, &ls);
    ls.time_assembly = seconds_since(t0);
    return solve_local_system(host, ls, options);
  });
}

}  // namespace
}  // namespace dynid

extern "C" __attribute__((visibility("default"))) const dynid::detail::DistributedBackend* dynid_distributed_backend(
    const dynid::detail::DistributedAbi* abi) {
  using namespace dynid;
  static const detail::DistributedBackend backend{&start_runtime, &world_rank, &world_size, &solve_elements,
                                                  &solve_matrices};
  return abi && *abi == detail::DistributedAbi{} ? &backend : nullptr;
}

#include <algorithm>
#include <cmath>
#include <string>

#include "dynid/mesh/error.hpp"
#include "dynid/solvers/sparse.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace dynid {

Assembler::Assembler(const ElementSource& source) : src_(source), n_(source.num_dofs()) {
  const int ne = source.num_elements();
  // Element DOF lists in CSR form (free DOFs only).
  std::vector<int> eptr(ne + 1, 0), edofs;
  {
    std::vector<int> d;
    for (int e = 0; e < ne; ++e) {
      source.element_dofs(e, &d);
      for (int g : d) {
        if (g >= n_) throw InputError("element " + std::to_string(e) + ": DOF " + std::to_string(g) + " >= number of DOFs " + std::to_string(n_));
        if (g >= 0) edofs.push_back(g);
      }
      eptr[e + 1] = static_cast<int>(edofs.size());
    }
  }
  // DOF -> elements (CSR, ascending element order).
  std::vector<int> dptr(n_ + 1, 0), delem(edofs.size());
  for (int g : edofs) ++dptr[g + 1];
  for (int i = 0; i < n_; ++i) dptr[i + 1] += dptr[i];
  {
    std::vector<int> fill(dptr.begin(), dptr.end() - 1);
    for (int e = 0; e < ne; ++e)
      for (int k = eptr[e]; k < eptr[e + 1]; ++k) delem[fill[edofs[k]]++] = e;
  }
  // Sparse elements (element_coupling): their coupled pairs per column (CSR), instead of all their DOFs.
  sparse_.assign(ne, 0);
  std::vector<int> xptr(n_ + 1, 0), xrows;
  {
    std::vector<std::pair<int, int>> pairs, global;
    std::vector<int> d;
    for (int e = 0; e < ne; ++e) {
      if (!source.element_coupling(e, &pairs)) continue;
      sparse_[e] = 1;
      source.element_dofs(e, &d);
      for (const auto& [a, b] : pairs) {
        if (a < 0 || b < 0 || a >= static_cast<int>(d.size()) || b >= static_cast<int>(d.size()))
          throw InputError("element " + std::to_string(e) + ": a coupled pair outside its " + std::to_string(d.size()) +
                           " DOFs");
        if (d[a] < 0 || d[b] < 0) continue;
        global.emplace_back(d[a], d[b]);
        global.emplace_back(d[b], d[a]);
      }
    }
    for (const auto& [i, j] : global) ++xptr[j + 1];
    for (int i = 0; i < n_; ++i) xptr[i + 1] += xptr[i];
    xrows.resize(global.size());
    std::vector<int> fill(xptr.begin(), xptr.end() - 1);
    for (const auto& [i, j] : global) xrows[fill[j]++] = i;
  }
  // Pattern: column j holds the DOFs of every dense element touching j, the DOFs sparse elements couple to j, and
  // the diagonal. Two passes (count, fill), each column independent, so the result does not depend on the thread
  // count.
  colptr_.assign(n_ + 1, 0);
  auto column_rows = [&](int j, std::vector<int>* rows) {
    rows->clear();
    rows->push_back(j);
    for (int k = dptr[j]; k < dptr[j + 1]; ++k) {
      const int e = delem[k];
      if (!sparse_[e]) rows->insert(rows->end(), edofs.begin() + eptr[e], edofs.begin() + eptr[e + 1]);
    }
    rows->insert(rows->end(), xrows.begin() + xptr[j], xrows.begin() + xptr[j + 1]);
    std::sort(rows->begin(), rows->end());
    rows->erase(std::unique(rows->begin(), rows->end()), rows->end());
  };
#pragma omp parallel
  {
    std::vector<int> rows;
#pragma omp for schedule(static)
    for (int j = 0; j < n_; ++j) {
      column_rows(j, &rows);
      colptr_[j + 1] = static_cast<int>(rows.size());
    }
  }
  for (int j = 0; j < n_; ++j) {
    if (static_cast<long long>(colptr_[j]) + colptr_[j + 1] > 2147483647LL)
      throw InputError("assembly: more than 2^31 - 1 nonzeros; the model is too large for 32-bit indices");
    colptr_[j + 1] += colptr_[j];
  }
  rows_.resize(colptr_[n_]);
#pragma omp parallel
  {
    std::vector<int> rows;
#pragma omp for schedule(static)
    for (int j = 0; j < n_; ++j) {
      column_rows(j, &rows);
      std::copy(rows.begin(), rows.end(), rows_.begin() + colptr_[j]);
    }
  }
  // Greedy colouring in element order: an element takes the smallest colour not used by an element sharing a
  // DOF with it. Sequential and deterministic.
  std::vector<int> color(ne, -1);
  std::vector<int> mark;  // mark[c] == e  <=> colour c is taken by a neighbour of e
  int ncolors = 0;
  for (int e = 0; e < ne; ++e) {
    for (int k = eptr[e]; k < eptr[e + 1]; ++k) {
      const int g = edofs[k];
      for (int q = dptr[g]; q < dptr[g + 1]; ++q) {
        const int c = color[delem[q]];
        if (c >= 0) mark[c] = e;
      }
    }
    int c = 0;
    while (c < ncolors && mark[c] == e) ++c;
    if (c == ncolors) {
      ++ncolors;
      mark.push_back(-1);
    }
    color[e] = c;
  }
  color_ptr_.assign(ncolors + 1, 0);
  for (int e = 0; e < ne; ++e) ++color_ptr_[color[e] + 1];
  for (int c = 0; c < ncolors; ++c) color_ptr_[c + 1] += color_ptr_[c];
  color_elems_.resize(ne);
  std::vector<int> fill(color_ptr_.begin(), color_ptr_.end() - 1);
  for (int e = 0; e < ne; ++e) color_elems_[fill[color[e]]++] = e;
}

SparseMatrix Assembler::pattern() const {
  SparseMatrix A(n_, n_);
  A.resizeNonZeros(static_cast<Eigen::Index>(rows_.size()));
  std::copy(colptr_.begin(), colptr_.end(), A.outerIndexPtr());
  std::copy(rows_.begin(), rows_.end(), A.innerIndexPtr());
  std::fill(A.valuePtr(), A.valuePtr() + rows_.size(), 0.0);
  return A;
}

void Assembler::assemble(SparseMatrix* K, SparseMatrix* M) const {
  if (K) *K = pattern();
  if (M) *M = pattern();
  std::string error;
  for (int c = 0; c + 1 < static_cast<int>(color_ptr_.size()); ++c) {
#pragma omp parallel
    {
      std::vector<int> dofs;
      Eigen::MatrixXd Ke, Me;
      std::vector<int> pos;
#pragma omp for schedule(static)
      for (int k = color_ptr_[c]; k < color_ptr_[c + 1]; ++k) {
        const int e = color_elems_[k];
        src_.element_dofs(e, &dofs);
        src_.element_matrices(e, K ? &Ke : nullptr, M ? &Me : nullptr);
        const int nd = static_cast<int>(dofs.size());
        const bool bad_size = (K && (Ke.rows() != nd || Ke.cols() != nd)) || (M && (Me.rows() != nd || Me.cols() != nd));
        const bool bad_value = !bad_size && ((K && !Ke.allFinite()) || (M && !Me.allFinite()));
        if (bad_size || bad_value) {
#pragma omp critical(dynid_assembly_error)
          if (error.empty())
            error = "element " + std::to_string(e) +
                    (bad_size ? ": element matrix size does not match its DOF count" : ": non-finite entry in its element matrix");
          continue;
        }
        // Positions of (dofs[a], dofs[b]) in the CSC arrays, by binary search in column dofs[b]; a sparse
        // element's zero entries need none (and may lie outside the pattern).
        pos.assign(static_cast<std::size_t>(nd) * nd, -1);
        bool outside = false;
        for (int b = 0; b < nd; ++b) {
          const int j = dofs[b];
          if (j < 0) continue;
          const int* first = rows_.data() + colptr_[j];
          const int* last = rows_.data() + colptr_[j + 1];
          for (int a = 0; a < nd; ++a) {
            const int i = dofs[a];
            if (i < 0) continue;
            if (sparse_[e] && (!K || Ke(a, b) == 0.0) && (!M || Me(a, b) == 0.0)) continue;
            const int* it = std::lower_bound(first, last, i);
            if (it == last || *it != i) {
              outside = true;
              continue;
            }
            pos[static_cast<std::size_t>(b) * nd + a] = static_cast<int>(it - rows_.data());
          }
        }
        if (outside) {
#pragma omp critical(dynid_assembly_error)
          if (error.empty())
            error = "element " + std::to_string(e) + ": a nonzero entry between DOFs its coupling leaves out";
          continue;
        }
        for (int b = 0; b < nd; ++b)
          for (int a = 0; a < nd; ++a) {
            const int p = pos[static_cast<std::size_t>(b) * nd + a];
            if (p < 0) continue;
            if (K) K->valuePtr()[p] += Ke(a, b);
            if (M) M->valuePtr()[p] += Me(a, b);
          }
      }
    }
  }
  if (!error.empty()) throw InputError("assembly: " + error);
}

void symmetric_multiply(const SparseMatrix& A, const double* x, double* y) {
  const int n = static_cast<int>(A.cols());
  const int* cp = A.outerIndexPtr();
  const int* ri = A.innerIndexPtr();
  const double* v = A.valuePtr();
#pragma omp parallel for schedule(static) if (n > 20000)
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int k = cp[i]; k < cp[i + 1]; ++k) s += v[k] * x[ri[k]];
    y[i] = s;
  }
}

void residual_forces(const SparseMatrix& K, const SparseMatrix& M, const Eigen::MatrixXd& Phi,
                     const Eigen::VectorXd& lambda, Eigen::MatrixXd* R) {
  const int n = static_cast<int>(K.rows());
  const Eigen::Index m = Phi.cols();
  if (M.rows() != n || Phi.rows() != n || lambda.size() != m)
    throw InputError("residual_forces: sizes of K, M, Phi and lambda do not match");
  const bool same = K.nonZeros() == M.nonZeros() &&
                    std::equal(K.outerIndexPtr(), K.outerIndexPtr() + n + 1, M.outerIndexPtr()) &&
                    std::equal(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros(), M.innerIndexPtr());
  R->resize(n, m);
  if (!same) {  // general patterns: two products
    *R = -(K * Phi) + (M * Phi) * lambda.asDiagonal();
    return;
  }
  const int* cp = K.outerIndexPtr();
  const int* ri = K.innerIndexPtr();
  const double* kv = K.valuePtr();
  const double* mv = M.valuePtr();
  // Row i of a symmetric matrix = column i: R(i, k) = sum_j (-K_ij + lambda_k M_ij) Phi(j, k). Row-major
  // copies keep the k loop contiguous.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor P = Phi;
  RowMajor out(n, m);
  const double* lam = lambda.data();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < n; ++i) {
    double* acc = out.data() + static_cast<std::size_t>(i) * m;
    for (Eigen::Index k = 0; k < m; ++k) acc[k] = 0.0;
    for (int p = cp[i]; p < cp[i + 1]; ++p) {
      const double* phi = P.data() + static_cast<std::size_t>(ri[p]) * m;
      const double kk = kv[p], mm = mv[p];
      for (Eigen::Index k = 0; k < m; ++k) acc[k] += (lam[k] * mm - kk) * phi[k];
    }
  }
  *R = out;
}

double norm1(const SparseMatrix& A) {
  double m = 0.0;
  for (int j = 0; j < A.outerSize(); ++j) {
    double s = 0.0;
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) s += std::abs(it.value());
    m = std::max(m, s);
  }
  return m;
}

}  // namespace dynid

// Test data spread over files, assembled into tests (see dynid/io/test_layout.hpp).
#include "dynid/io/test_layout.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "dynid/io/modal_data_io.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/text_util.hpp"

namespace dynid {

namespace {

std::string fmt_num(double v) { return internal::format_number(v, 6); }

// One channel's samples of one record, and where they came from.
struct Piece {
  std::size_t file = 0;
  std::string where;  // "a.uff: dataset 58 at line 120" or "b.csv: column 3"
  Channel ch;
  Eigen::VectorXd y;
  double fs = 0, x0 = 0;
  bool has_ref = false;
  MeasuredDof ref;
};

std::string key_of(const Channel& c) {
  return (c.dof.node != 0 ? to_string(c.dof) : "'" + c.name + "'") + (c.input ? " force" : "");
}

bool same_rate(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)); }

std::string sampling_text(double fs, Eigen::Index ns) { return fmt_num(fs) + " Hz, " + std::to_string(ns) + " samples"; }

// Pieces of one file.
void pieces_of(const TestData& d, std::size_t file, const std::string& path, std::vector<Piece>* out) {
  if (d.kind == TestData::Kind::kUff) {
    for (const UffDataset& ds : d.uff.datasets) {
      const Uff58* u = std::get_if<Uff58>(&ds.data);
      if (!u || u->function_type != 1) continue;
      const std::string where = path + ": dataset 58 at line " + std::to_string(ds.first_line);
      if (!u->even) throw InputError(where + ": time response with uneven abscissa; dynid needs evenly sampled data");
      if (u->is_complex()) throw InputError(where + ": time response with complex values");
      if (!(u->dx > 0)) throw InputError(where + ": time step " + fmt_num(u->dx) + " is not > 0");
      Piece p;
      p.file = file;
      p.where = where;
      double sign = 1;
      p.ch = uff_channel(*u, &sign);
      p.y = sign * u->y.real();
      p.fs = 1.0 / u->dx;
      p.x0 = u->x_min;
      p.has_ref = uff_reference(*u, &p.ref);
      out->push_back(std::move(p));
    }
    return;
  }
  const Recording& r = d.recording;
  const double x0 = d.table.x.size() == (r.records.empty() ? 0 : r.records[0].rows()) && d.table.x.size() > 0 ? d.table.x[0] : 0.0;
  for (std::size_t k = 0; k < r.records.size(); ++k)
    for (int c = 0; c < r.num_channels(); ++c) {
      Piece p;
      p.file = file;
      p.where = path + ": column " + std::to_string(c + 2) + " ('" + r.channels[static_cast<std::size_t>(c)].name + "')";
      p.ch = r.channels[static_cast<std::size_t>(c)];
      p.y = r.records[k].col(c);
      p.fs = r.sample_rate_hz;
      p.x0 = x0;
      out->push_back(std::move(p));
    }
}

struct Group {
  bool has_ref = false;
  MeasuredDof ref;
  double fs = 0;
  Eigen::Index ns = 0;
  std::vector<std::size_t> pieces;
};

std::string group_name(const Group& g, std::size_t index) {
  return "test " + std::to_string(index + 1) + (g.has_ref ? " (reference " + to_string(g.ref) + ")" : "");
}

void assemble_recordings(const std::vector<TestData>& files, const std::vector<std::string>& paths, TestSet* set) {
  std::vector<Piece> pieces;
  for (std::size_t f = 0; f < files.size(); ++f)
    if (files[f].kind == TestData::Kind::kUff || files[f].kind == TestData::Kind::kTimeHistory) pieces_of(files[f], f, paths[f], &pieces);
  if (pieces.empty()) throw InputError("no time responses in " + paths[0] + (paths.size() > 1 ? " and the other files" : ""));
  // Rule 2: a file with responses and force channels at one DOF, but no references: that DOF.
  for (std::size_t f = 0; f < files.size(); ++f) {
    std::set<std::string> force_dofs;
    MeasuredDof force;
    bool responses = false, unreferenced = false;
    for (const Piece& p : pieces) {
      if (p.file != f) continue;
      if (p.ch.input && p.ch.dof.node != 0) force_dofs.insert(to_string(p.ch.dof)), force = p.ch.dof;
      responses = responses || !p.ch.input;
      unreferenced = unreferenced || !p.has_ref;
    }
    if (!unreferenced || !responses || force_dofs.size() != 1) continue;
    for (Piece& p : pieces)
      if (p.file == f && !p.has_ref) p.has_ref = true, p.ref = force;
    set->notes.push_back(paths[f] + ": no reference DOF in its datasets; its force channel " + to_string(force) + " taken as the reference");
  }
  // Rule 3: groups by reference, sampling rate and length.
  std::vector<Group> groups;
  auto find_group = [&](bool has_ref, const MeasuredDof& ref, double fs, Eigen::Index ns) -> Group* {
    for (Group& g : groups)
      if (g.has_ref == has_ref && (!has_ref || g.ref == ref) && same_rate(g.fs, fs) && g.ns == ns) return &g;
    return nullptr;
  };
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Piece& p = pieces[i];
    Group* g = find_group(p.has_ref, p.ref, p.fs, p.y.size());
    if (!g) {
      groups.push_back({p.has_ref, p.ref, p.fs, p.y.size(), {}});
      g = &groups.back();
    }
    g->pieces.push_back(i);
  }
  // Unreferenced groups join the one referenced group with their sampling.
  for (std::size_t a = 0; a < groups.size(); ++a) {
    if (groups[a].has_ref || groups[a].pieces.empty()) continue;
    std::vector<std::size_t> match;
    for (std::size_t b = 0; b < groups.size(); ++b)
      if (groups[b].has_ref && same_rate(groups[b].fs, groups[a].fs) && groups[b].ns == groups[a].ns) match.push_back(b);
    if (match.size() == 1) {
      Group& to = groups[match[0]];
      to.pieces.insert(to.pieces.end(), groups[a].pieces.begin(), groups[a].pieces.end());
      std::sort(to.pieces.begin(), to.pieces.end());
      std::set<std::string> fl;
      for (std::size_t i : groups[a].pieces) fl.insert(paths[pieces[i].file]);
      std::string list;
      for (const std::string& f : fl) list += (list.empty() ? "" : ", ") + f;
      set->notes.push_back(list + ": no reference DOF; joined the test with reference " + to_string(to.ref) + " (the one with their sampling)");
      groups[a].pieces.clear();
    } else if (match.size() > 1) {
      std::string refs;
      for (std::size_t b : match) refs += (refs.empty() ? "" : ", ") + to_string(groups[b].ref);
      throw InputError(pieces[groups[a].pieces[0]].where + " (channel " + key_of(pieces[groups[a].pieces[0]].ch) +
                       "): no reference DOF, and the tests with references " + refs +
                       " have its sampling: which one it belongs to is ambiguous; write the reference (hammer or shaker DOF) into "
                       "record 6 of its datasets, or identify the tests one at a time");
    }
  }
  groups.erase(std::remove_if(groups.begin(), groups.end(), [](const Group& g) { return g.pieces.empty(); }), groups.end());
  // Channel order: first appearance over all files.
  std::map<std::string, std::size_t> rank;
  for (const Piece& p : pieces) rank.emplace(key_of(p.ch), rank.size());
  // Rule 4: records within each test.
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    const Group& g = groups[gi];
    TestGroup tg;
    tg.has_reference = g.has_ref;
    tg.reference = g.ref;
    const std::string name = group_name(g, gi);
    std::map<std::size_t, std::vector<std::size_t>> by_channel;  // rank -> pieces in order
    std::set<std::size_t> file_set;
    for (std::size_t i : g.pieces) {
      by_channel[rank[key_of(pieces[i].ch)]].push_back(i);
      file_set.insert(pieces[i].file);
    }
    for (std::size_t f : file_set) tg.files.push_back(paths[f]);
    const double tol = 0.5 / g.fs;
    std::vector<double> starts;
    for (std::size_t i : g.pieces) {
      bool known = false;
      for (double s : starts) known = known || std::abs(s - pieces[i].x0) <= tol;
      if (!known) starts.push_back(pieces[i].x0);
    }
    std::sort(starts.begin(), starts.end());
    const bool by_start = starts.size() > 1;
    // Records of each channel.
    std::vector<std::vector<std::size_t>> recs_of;  // per channel (rank order), piece per record
    std::vector<std::size_t> ranks;
    bool ok = true;
    for (const auto& [rk, list] : by_channel) {
      ranks.push_back(rk);
      if (!by_start) {
        recs_of.push_back(list);
        continue;
      }
      std::vector<std::size_t> per(starts.size(), pieces.size());
      for (std::size_t i : list) {
        const std::size_t s = static_cast<std::size_t>(std::lower_bound(starts.begin(), starts.end(), pieces[i].x0 - tol) - starts.begin());
        if (per[s] != pieces.size()) {
          set->problems.push_back(pieces[i].where + ": " + name + ", channel " + key_of(pieces[i].ch) + " has a second record starting at " +
                                  fmt_num(pieces[i].x0) + " s (the first is " + pieces[per[s]].where +
                                  "); records of one test are told apart by their start times: give each its own");
          ok = false;
        }
        per[s] = i;
      }
      for (std::size_t s = 0; s < starts.size(); ++s)
        if (per[s] == pieces.size()) {
          set->problems.push_back(pieces[list[0]].where + ": " + name + ", channel " + key_of(pieces[list[0]].ch) + " has no record starting at " +
                                  fmt_num(starts[s]) + " s, which other channels of the test have; give every channel the same records (hits)");
          ok = false;
        }
      recs_of.push_back(per);
    }
    // Every channel the same number of records: the most common count is the test's.
    std::map<std::size_t, int> counts;
    for (const auto& r : recs_of) ++counts[r.size()];
    std::size_t n_rec = 0;
    int best = -1;
    for (const auto& [n, c] : counts)
      if (c > best || (c == best && n > n_rec)) best = c, n_rec = n;
    for (std::size_t c = 0; c < recs_of.size(); ++c) {
      if (recs_of[c].size() == n_rec) continue;
      std::string wh;
      for (std::size_t i : recs_of[c]) wh += (wh.empty() ? "" : "; ") + pieces[i].where;
      set->problems.push_back(name + ": channel " + key_of(pieces[recs_of[c][0]].ch) + " has " + std::to_string(recs_of[c].size()) +
                              " records (" + wh + "), the other channels " + std::to_string(n_rec) +
                              (recs_of[c].size() > n_rec ? ": the files may hold more than one test (give each dataset its reference DOF, "
                                                           "UFF 58 record 6) or a record twice"
                                                         : ": a record (hit) is missing; give every channel the same records or leave the channel out"));
      ok = false;
    }
    tg.ok = ok;
    Recording& r = tg.recording;
    r.sample_rate_hz = g.fs;
    r.source = tg.files.size() == 1 ? tg.files[0] : name + " (" + std::to_string(tg.files.size()) + " files)";
    for (const auto& list : recs_of) r.channels.push_back(pieces[list[0]].ch);
    if (ok) {
      for (std::size_t k = 0; k < n_rec; ++k) {
        Eigen::MatrixXd m(g.ns, static_cast<Eigen::Index>(recs_of.size()));
        for (std::size_t c = 0; c < recs_of.size(); ++c) m.col(static_cast<Eigen::Index>(c)) = pieces[recs_of[c][k]].y;
        r.records.push_back(std::move(m));
      }
      r.validate(r.source);
    }
    set->tests.push_back(std::move(tg));
  }
  // Tests identified together (a roving hammer, records of one ambient run) must measure the same responses.
  const TestGroup* first = nullptr;
  for (const TestGroup& t : set->tests) {
    if (t.recording.output_channels().empty()) {
      std::string others;
      for (const TestGroup& u : set->tests)
        if (&u != &t && !u.recording.output_channels().empty())
          others += (others.empty() ? "" : ", ") + sampling_text(u.recording.sample_rate_hz, u.recording.records.empty() ? 0 : u.recording.records[0].rows()) +
                    (u.has_reference ? " reference " + to_string(u.reference) : "");
      const Group* g = nullptr;
      for (std::size_t gi = 0; gi < set->tests.size(); ++gi)
        if (&set->tests[gi] == &t) g = &groups[gi];
      set->problems.push_back(pieces[g->pieces[0]].where + ": force channels without responses (" + sampling_text(g->fs, g->ns) +
                              (g->has_ref ? ", reference " + to_string(g->ref) : ", no reference") + ")" +
                              (others.empty() ? "" : "; the responses are in tests with " + others) +
                              ": give the force the responses' sampling, length and reference, or leave its file out");
      continue;
    }
    if (!first) {
      first = &t;
      continue;
    }
    std::set<std::string> a, b;
    for (int c : first->recording.output_channels()) a.insert(key_of(first->recording.channels[static_cast<std::size_t>(c)]));
    for (int c : t.recording.output_channels()) b.insert(key_of(t.recording.channels[static_cast<std::size_t>(c)]));
    if (a == b) continue;
    std::string missing, extra;
    for (const std::string& k : a)
      if (!b.count(k)) missing += (missing.empty() ? "" : ", ") + k;
    for (const std::string& k : b)
      if (!a.count(k)) extra += (extra.empty() ? "" : ", ") + k;
    set->problems.push_back(t.recording.source + ": its responses differ from those of " + first->recording.source +
                            (missing.empty() ? "" : " (it lacks " + missing + ")") + (extra.empty() ? "" : " (it has " + extra + " more)") +
                            "; tests identified together (hammer locations, runs) must measure the same responses: check the "
                            "references, sampling and lengths of its files, or identify it on its own");
  }
}

}  // namespace

std::string TestGroup::summary() const {
  const Recording& r = recording;
  const std::vector<int> ins = r.input_channels(), outs = r.output_channels();
  std::string s = std::to_string(outs.size()) + (outs.size() == 1 ? " output" : " outputs");
  if (ins.empty()) s += " (output-only)";
  else {
    s += ins.size() == 1 ? " + force " : " + forces ";
    for (std::size_t k = 0; k < ins.size(); ++k) {
      const Channel& c = r.channels[static_cast<std::size_t>(ins[k])];
      s += (k ? ", " : "") + (c.dof.node != 0 ? to_string(c.dof) : "'" + c.name + "'");
    }
  }
  const Eigen::Index ns = r.records.empty() ? 0 : r.records[0].rows();
  s += ", " + std::to_string(r.records.size()) + (r.records.size() == 1 ? " record of " : " records of ") + std::to_string(ns) + " samples at " +
       fmt_num(r.sample_rate_hz) + " Hz";
  if (has_reference) s += ", reference " + to_string(reference);
  s += ", from " + std::to_string(files.size()) + (files.size() == 1 ? " file" : " files");
  return s;
}

void TestSet::require_consistent() const {
  if (problems.empty()) return;
  std::string m = problems.size() == 1 ? problems[0] : std::to_string(problems.size()) + " inconsistencies in the test files:";
  if (problems.size() > 1)
    for (const std::string& p : problems) m += "\n  " + p;
  throw InputError(m);
}

std::vector<Recording> TestSet::recordings() const {
  std::vector<Recording> out;
  for (const TestGroup& t : tests)
    if (t.ok) out.push_back(t.recording);
  return out;
}

TestSet assemble_test_set(const std::vector<TestData>& files, const std::vector<std::string>& paths, const TestSetOptions& o) {
  if (files.empty()) throw InputError("no test files given");
  if (paths.size() != files.size()) throw InputError("assemble_test_set: one path per file");
  TestSet set;
  set.files = paths;
  // What each file holds.
  std::vector<std::size_t> time, frf_uff, frf_text, spectra;
  for (std::size_t f = 0; f < files.size(); ++f) {
    const TestData& d = files[f];
    switch (d.kind) {
      case TestData::Kind::kUff: {
        bool has_frf = false, has_time = false;
        for (const UffDataset& ds : d.uff.datasets)
          if (const Uff58* u = std::get_if<Uff58>(&ds.data)) {
            has_frf = has_frf || u->function_type == 4;
            has_time = has_time || u->function_type == 1;
          }
        if (has_frf) {
          frf_uff.push_back(f);
          if (has_time) set.notes.push_back(paths[f] + ": holds FRFs and time responses; its FRFs are used");
        } else if (has_time) {
          time.push_back(f);
        } else {
          throw InputError(paths[f] + ": holds no time responses (58, function type 1) and no FRFs (58, type 4)");
        }
        break;
      }
      case TestData::Kind::kTimeHistory:
        time.push_back(f);
        if (!d.how.empty()) set.read_as.push_back(paths[f] + ": time history (" + d.how + ")");
        break;
      case TestData::Kind::kFrf:
        frf_text.push_back(f);
        set.read_as.push_back(paths[f] + ": FRF (" + d.how + ")");
        break;
      case TestData::Kind::kSpectrum:
        spectra.push_back(f);
        if (!d.how.empty()) set.read_as.push_back(paths[f] + ": spectrum (" + d.how + ")");
        break;
    }
  }
  const int kinds = !time.empty() + !(frf_uff.empty() && frf_text.empty()) + !spectra.empty();
  if (kinds > 1) {
    auto first_of = [&](const std::vector<std::size_t>& v) { return v.empty() ? std::string() : paths[v[0]]; };
    std::string list;
    if (!time.empty()) list += "time histories (" + first_of(time) + ")";
    if (!frf_uff.empty() || !frf_text.empty()) list += std::string(list.empty() ? "" : ", ") + "FRFs (" + first_of(frf_uff.empty() ? frf_text : frf_uff) + ")";
    if (!spectra.empty()) list += std::string(list.empty() ? "" : ", ") + "spectra (" + first_of(spectra) + ")";
    throw InputError("the files hold " + list + "; give one kind at a time (time histories, FRFs, or a spectrum alone)");
  }
  if (!spectra.empty()) {
    if (files.size() > 1) throw InputError(paths[spectra[0]] + ": a magnitude spectrum is read on its own (peak picking); give it alone");
    set.kind = TestSet::Kind::kSpectrum;
    set.spectrum = files[spectra[0]].table;
    return set;
  }
  if (!frf_uff.empty() || !frf_text.empty()) {
    if (!frf_uff.empty() && !frf_text.empty())
      throw InputError(paths[frf_text[0]] + ": FRF text files and UFF FRF files (" + paths[frf_uff[0]] + ") given together; give FRFs of one format");
    set.kind = TestSet::Kind::kFrf;
    if (!frf_uff.empty()) {
      std::vector<const UffFile*> u;
      for (std::size_t f : frf_uff) u.push_back(&files[f].uff);
      set.frf = uff_frf(u);
    } else {
      std::vector<TextTable> tables;
      for (std::size_t f : frf_text) tables.push_back(files[f].table);
      std::vector<MeasuredDof> outs = o.frf_outputs, ins = o.frf_inputs;
      std::size_t total = 0;
      for (const TextTable& t : tables) total += static_cast<std::size_t>(t.columns.cols() / 2);
      if (outs.empty()) {
        for (std::size_t k = 0; k < total; ++k) outs.push_back({static_cast<int>(k) + 1, Dof::UX});
        set.notes.push_back("FRF text files carry no DOFs: FRF k is taken as output point k (1ux .. " + std::to_string(total) +
                            "ux) over one common reference; give the outputs and inputs (--outputs, --inputs) to say otherwise");
      }
      if (ins.empty()) ins.push_back({0, Dof::UX});
      set.frf = frf_of_tables(tables, outs, ins);
    }
    return set;
  }
  set.kind = TestSet::Kind::kRecordings;
  assemble_recordings(files, paths, &set);
  return set;
}

TestSet read_test_set(const std::vector<std::string>& paths, const TestSetOptions& o) {
  std::vector<TestData> files;
  for (const std::string& p : paths) files.push_back(read_test_data(p, o.sample_rate_hz, o.kind, o.limits));
  return assemble_test_set(files, paths, o);
}

}  // namespace dynid

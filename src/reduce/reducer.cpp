#include "gyrocal/reduce/reducer.hpp"

// The reducer's public face (reduce/reducer.hpp): rows pushed in, the reduction finished (the dwells kept in
// time order, the positions reduced, the refusals of a record without a planned dwell). Its work is cut by
// job: reducer_state.hpp, steady_runs.cpp, dwell_building.cpp, plan_matching.cpp, read_ahead.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "reducer_state.hpp"

namespace gyrocal {

Reducer::Reducer(const PlannedTest& plan, const ReduceOptions& options, std::string source_name)
    : state_(std::make_unique<State>()) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("reduction options: " + error + ".");
  state_->plan = plan.spec;
  state_->options = options;
  state_->source = std::move(source_name);
  state_->dt_planned = 1.0 / plan.spec.sample_rate_hz;
  state_->reference_rate = reference_rate_rad_s(plan.spec, plan.reference_rate_rad_s);
  if (state_->reference_rate == 0.0 && !(plan.spec.static_hold_s > 0.0))
    throw Error(
        "the plan has no non-zero rate, no [test] static_hold_s and no reference rate to size the static "
        "holds.");
  check_test_feasible(plan.spec, options, state_->reference_rate);
  check_calibration_memory(plan.spec, options);
}

Reducer::~Reducer() = default;

void Reducer::set_threaded_accumulation(bool threaded) {
  if (state_->rows > 0) throw Error("Reducer::set_threaded_accumulation: only before the first row.");
  state_->feed.emplace(threaded);
}

void Reducer::set_output_columns(const std::vector<std::string>& names) {
  if (state_->rows > 0) throw Error("Reducer::set_output_columns: only before the first row.");
  if (names.empty() || names.size() > limits::kMaxOutputColumns)
    throw Error(
        fmt::format("{}: a record is reduced with 1 to {} output columns (limits::kMaxOutputColumns), "
                    "not {}.",
                    state_->source, limits::kMaxOutputColumns, names.size()));
  state_->outputs = names.size();
  state_->output_names = names.size() > 1 ? names : std::vector<std::string>{};
}

void Reducer::set_increments(bool increments) {
  if (state_->rows > 0) throw Error("Reducer::set_increments: only before the first row.");
  state_->increments = increments;
}

void Reducer::set_record_layout(const std::optional<RecordLayout>& layout) {
  state_->layout = layout;
}

void Reducer::push(const RecordSample& s) {
  push_unsummarised(s);
  state_->summary.add(s);
}

std::size_t Reducer::dwells_held() const {
  return state_->dwells.size();
}

void Reducer::set_summary(const RecordSummary& summary) {
  state_->summary = summary;
}

Reduction Reducer::finish() {
  if (state_->outputs != 1)
    throw Error(fmt::format("{}: the reducer reads {} output columns; finish_channels() reduces them.",
                            state_->source, state_->outputs));
  Reduction out = state_->finish_first_column();
  state_->check_degrees_of_freedom(out, std::string());
  return out;
}

std::vector<Reduction> Reducer::finish_channels() {
  State& st = *state_;
  std::vector<Reduction> out;
  out.reserve(st.outputs);
  // The dwells are moved into the first column's reduction in time order: keep each one's other columns
  // beside it.
  out.push_back(st.finish_first_column());
  const Reduction& first = out.front();
  for (std::size_t c = 1; c < st.outputs; ++c) {
    Reduction r = first;
    r.outliers = 0;
    for (std::size_t i = 0; i < r.dwells.size(); ++i) {
      r.dwells[i].output = std::move(st.chosen_more[i][c - 1]);
      r.outliers += r.dwells[i].output.outliers;
    }
    for (ReducedPosition& p : r.positions) {
      const Position planned{p.index, p.rate_rad_s, p.beta_rad, p.gamma_rad, p.counter_rate_offset_rad_s};
      p = reduced_position(planned, r.dwells[static_cast<std::size_t>(p.dwell)], p.dwell,
                           static_cast<int>(c));
    }
    out.push_back(std::move(r));
  }
  st.chosen_more.clear();
  for (std::size_t c = 0; c < out.size(); ++c)
    st.check_degrees_of_freedom(out[c], st.output_names.size() > c ? st.output_names[c] : std::string());
  return out;
}

Reduction Reducer::State::finish_first_column() {
  State& st = *this;
  while (st.run) st.end_run("the record ends", State::Ending::kRecordEnds);
  Reduction out;
  out.samples_read = st.rows;
  out.warnings = st.warnings.lines();
  if (st.offset_dwells > 0)
    out.warnings.push_back(
        fmt::format("{}: in {} dwell{} the main axis turned up to {:.2e} (relative) off the planned rate; "
                    "the measured rates "
                    "are used.",
                    st.source, st.offset_dwells, st.offset_dwells > 1 ? "s" : "", st.worst_rate_offset));
  // One dwell per (rate, beta) or (0, beta, gamma): the longest if the record has several (kept as they were
  // found, State::keep), in time order.
  for (std::string& w : st.repeats.lines()) out.warnings.push_back(std::move(w));
  std::vector<std::size_t> in_time_order(st.dwells.size());
  for (std::size_t i = 0; i < in_time_order.size(); ++i) in_time_order[i] = i;
  std::sort(in_time_order.begin(), in_time_order.end(),
            [&](std::size_t a, std::size_t b) { return st.dwell_serial[a] < st.dwell_serial[b]; });
  std::map<DwellKey, int> chosen;  // the dwell of each key, numbered as in out.dwells
  for (std::size_t i : in_time_order) {
    // Moved, not copied: a dwell holds a few numbers a revolution (docs/performance.md).
    chosen[dwell_key(st.dwells[i])] = static_cast<int>(out.dwells.size());
    out.dwells.push_back(std::move(st.dwells[i]));
    st.chosen_more.push_back(std::move(st.more_outputs[i]));
    out.samples_used += out.dwells.back().samples;
    out.outliers += out.dwells.back().output.outliers;
    out.gaps += out.dwells.back().gaps;
    out.encoder_glitch_rows += out.dwells.back().quality.encoder_glitch_rows;
    if (st.increments)
      out.increments_dropped =
          out.increments_dropped.value_or(0) + out.dwells.back().quality.increments_dropped;
  }
  if (st.increments && !out.increments_dropped) out.increments_dropped = 0;
  st.dwells.clear();
  st.more_outputs.clear();
  st.dwell_of_key.clear();
  out.rejected = st.rejected;
  std::sort(out.rejected.begin(), out.rejected.end(),
            [](const RejectedRun& a, const RejectedRun& b) { return a.start_s < b.start_s; });
  std::vector<std::string> missing;
  for (const Position& p : test_positions(st.plan)) {
    const bool is_static = p.rate_rad_s == 0.0 && p.counter_rate_offset_rad_s == 0.0;
    const auto key =
        std::make_tuple(p.rate_rad_s, p.counter_rate_offset_rad_s, p.beta_rad, is_static ? p.gamma_rad : 0.0);
    const auto it = chosen.find(key);
    if (it == chosen.end()) {
      missing.push_back(
          fmt::format("position {} (rate {} rad/s, {}beta {} deg, gamma {} deg): {}", p.index, p.rate_rad_s,
                      p.counter_rate_offset_rad_s != 0.0
                          ? fmt::format("counter rate offset {} rad/s, ", p.counter_rate_offset_rad_s)
                          : std::string(),
                      p.beta_rad * kRadToDeg, p.gamma_rad * kRadToDeg, st.why_missing(p)));
      continue;
    }
    const int di = it->second;
    out.positions.push_back(reduced_position(p, out.dwells[static_cast<std::size_t>(di)], di));
  }
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < missing.size() && i < 4; ++i) list += (i ? "; " : "") + missing[i];
    if (missing.size() > 4) list += fmt::format("; and {} more", missing.size() - 4);
    throw Error(fmt::format("{}: the record has no usable dwell for {} planned position{}: {}. {}", st.source,
                            missing.size(), missing.size() > 1 ? "s" : "", list,
                            st.summary.describe(st.plan, st.layout, st.rejected, st.dwells_found)));
  }
  return out;
}

void Reducer::State::check_degrees_of_freedom(Reduction& r, const std::string& column) const {
  const std::string in_column = column.empty() ? std::string() : fmt::format(" (output {})", column);
  // A standard error is the scatter between revolutions (or batches) about a line: without a degree of
  // freedom left there is no measurement of the noise, and no number may stand in for one
  // (docs/calibration.md, "Degrees of freedom").
  int zero = 0;
  for (const Dwell& d : r.dwells) {
    if (d.output.dof > 0.0) continue;
    // The scatter is about a mean (and a drift), and at a counter rate offset also the heading's sweep.
    const int needed =
        d.is_static
            ? 2
            : (options.linear_drift ? 3 : 2) +
                  (heading_sweep_rad_s(d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s) != 0.0 ? 2
                                                                                                         : 0);
    if (d.output.revolutions >= needed) {
      // Enough revolutions, but their scatter overflowed: outputs whose squares leave a double's range (a
      // record's reader refuses them, limits::kOutputMagnitude; a caller pushing samples may not have).
      double largest = 0.0;
      for (double v : d.output.value)
        if (!(std::abs(v) <= largest)) largest = std::abs(v);
      throw Error(fmt::format(
          "{}: at t = {:.6f} s the {} at {} rad/s, beta {:.4f} deg{} has {} complete {}, but the scatter "
          "between "
          "them is not a finite number: its outputs reach {:g}, whose squares leave a double's range (an "
          "output is at most {:g} in magnitude, limits::kOutputMagnitude).",
          source, d.first_time_s, d.is_static ? "static hold" : "dwell", d.planned_rate_rad_s,
          d.beta_rad * kRadToDeg, in_column, d.output.revolutions, d.is_static ? "batches" : "revolutions",
          largest, limits::kOutputMagnitude));
    }
    throw Error(fmt::format(
        "{}: at t = {:.6f} s the {} at {} rad/s, beta {:.4f} deg{} has {} complete {}, too few for a "
        "standard "
        "error from the scatter between them; it needs at least {}{}.",
        source, d.first_time_s, d.is_static ? "static hold" : "dwell", d.planned_rate_rad_s,
        d.beta_rad * kRadToDeg, in_column, d.output.revolutions, d.is_static ? "batches" : "revolutions",
        needed,
        d.is_static ? ""
        : options.method == ReduceOptions::Method::kWindowMean
            ? ": raise [test] revolutions (window means count a revolution only when it passes through every "
              "window, so a dwell's first or last may not count)"
            : fmt::format(" ([test] revolutions = {} or more)", needed)));
  }
  for (const ReducedPosition& p : r.positions)
    if (p.std_err == 0.0) ++zero;
  if (zero > 0)
    r.warnings.push_back(
        fmt::format("{}: {} position{}{} show no scatter at all between revolutions: a "
                    "noise-free record, whose uncertainties mean nothing.",
                    source, zero, zero > 1 ? "s" : "", in_column));
}

ReducedPosition reduced_position(const Position& p, const Dwell& d, int dwell_index, int channel) {
  int slot = 0;
  for (std::size_t k = 0; k < d.gammas_rad.size(); ++k)
    if (d.gammas_rad[k] == p.gamma_rad) slot = static_cast<int>(k);
  const auto k = static_cast<std::size_t>(slot);
  ReducedPosition rp;
  rp.index = p.index;
  rp.rate_rad_s = p.rate_rad_s;
  rp.beta_rad = p.beta_rad;
  rp.gamma_rad = p.gamma_rad;
  rp.counter_rate_offset_rad_s = p.counter_rate_offset_rad_s;
  rp.mean = d.output.value[k];
  rp.std_err = d.output.std_err[k];
  rp.samples = d.output.samples[k];
  rp.outliers = d.output.outliers;
  rp.dwell = dwell_index;
  rp.gamma_slot = slot;
  rp.channel = channel;
  return rp;
}

}  // namespace gyrocal

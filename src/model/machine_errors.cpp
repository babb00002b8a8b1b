#include "gyrocal/model/machine_errors.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"

namespace gyrocal {
namespace {

using E = CentrifugeErrors;
using K = MachineErrorKind;
constexpr double kArcsec = kArcsecToRad;

// Typical magnitudes (docs/sensitivity.md): 1 arcsec for angles and wobbles, 1 um runout, 10 um radius
// error, 1e-7 m/(rad/s)^2 stretch (10 um at 9.9 rad/s), 1e-6 rad/s rate mismatch, 1 mm lever arm.
MachineErrorField constant(std::string_view name, std::string_view unit, std::string_view suffix,
                           double to_si, double typical, std::string_view comment, double E::*member) {
  return {name, unit, suffix, to_si, typical, K::kConstant, comment, member, nullptr, nullptr};
}
MachineErrorField series(std::string_view name, std::string_view unit, std::string_view suffix, double to_si,
                         double typical, std::string_view comment, HarmonicSeries E::*member) {
  return {name, unit, suffix, to_si, typical, K::kSeries, comment, nullptr, member, nullptr};
}
MachineErrorField vector(std::string_view name, std::string_view unit, std::string_view suffix, double to_si,
                         double typical, std::string_view comment, Eigen::Vector3d E::*member) {
  return {name, unit, suffix, to_si, typical, K::kVector, comment, nullptr, nullptr, member};
}

/// An error added after the sensitivity study's rows were set (issue 28): studied where configured.
MachineErrorField acquisition(MachineErrorField f) {
  f.studied_when_zero = false;
  return f;
}

/// The acquisition's timing ([record] output_delay_s; docs/calibration.md, "The acquisition's timing"): a
/// delay >= 0, s, up to limits::kOutputDelayS; 1 us typical (20 us shifts a 12 rad/s first harmonic by 2.4e-4
/// rad).
MachineErrorField output_delay() {
  MachineErrorField f = acquisition(
      constant("output_delay", "s", "s", 1.0, 1e-6,
               "the output is stamped this long after the instant it was sensed (a filter's group delay), s",
               &E::output_delay_s));
  f.section = MachineErrorSection::kRecord;
  f.limit_si = limits::kOutputDelayS;
  f.limit_reason =
      "limits::kOutputDelayS: an acquisition filter's group delay is microseconds to milliseconds; a longer "
      "offset is a clock's, to be corrected in the time column";
  f.non_negative = true;
  return f;
}

std::vector<MachineErrorField> make_fields() {
  return {
      constant("base_tilt_x", "arcsec", "arcsec", kArcsec, kArcsec,
               "tilt of the base about x (North), arcsec", &E::base_tilt_x_rad),
      constant("base_tilt_y", "arcsec", "arcsec", kArcsec, kArcsec, "tilt of the base about y (West), arcsec",
               &E::base_tilt_y_rad),
      constant("main_perpendicularity_x", "arcsec", "arcsec", kArcsec, kArcsec,
               "main axis tilt about x, arcsec", &E::main_perpendicularity_x_rad),
      constant("main_perpendicularity_y", "arcsec", "arcsec", kArcsec, kArcsec,
               "main axis tilt about y, arcsec", &E::main_perpendicularity_y_rad),
      series("main_wobble_x", "arcsec", "arcsec", kArcsec, kArcsec,
             "main axis wobble about x, harmonics of theta, arcsec", &E::main_wobble_x_rad),
      series("main_wobble_y", "arcsec", "arcsec", kArcsec, kArcsec,
             "main axis wobble about y, harmonics of theta, arcsec", &E::main_wobble_y_rad),
      series("main_runout_x", "m", "m", 1.0, 1e-6, "main axis runout along x, harmonics of theta, m",
             &E::main_runout_x_m),
      series("main_runout_y", "m", "m", 1.0, 1e-6, "main axis runout along y, harmonics of theta, m",
             &E::main_runout_y_m),
      constant("radius_error", "m", "m", 1.0, 1e-5, "added to R0, m", &E::radius_error_m),
      constant("radius_stretch", "m/(rad/s)^2", "m_per_rad2_s2", 1.0, 1e-7,
               "radius growth per omega^2, m/(rad/s)^2", &E::radius_stretch_m_per_rad2_s2),
      constant("counter_perpendicularity_x", "arcsec", "arcsec", kArcsec, kArcsec,
               "counter-rotating platform tilt about x, arcsec", &E::counter_perpendicularity_x_rad),
      constant("counter_perpendicularity_y", "arcsec", "arcsec", kArcsec, kArcsec,
               "counter-rotating platform tilt about y, arcsec", &E::counter_perpendicularity_y_rad),
      series("counter_wobble_x", "arcsec", "arcsec", kArcsec, kArcsec,
             "counter platform wobble about x, harmonics of psi_r, arcsec", &E::counter_wobble_x_rad),
      series("counter_wobble_y", "arcsec", "arcsec", kArcsec, kArcsec,
             "counter platform wobble about y, harmonics of psi_r, arcsec", &E::counter_wobble_y_rad),
      constant("counter_rate_mismatch", "rad/s", "rad_s", 1.0, 1e-6,
               "delta omega: platform heading drift about Up, rad/s", &E::counter_rate_mismatch_rad_s),
      acquisition(constant("counter_angle_error", "arcsec", "arcsec", kArcsec, kArcsec,
                           "added to the counter encoder's psi_r (its zero's error), arcsec",
                           &E::counter_angle_error_rad)),
      constant("position_perpendicularity_x", "arcsec", "arcsec", kArcsec, kArcsec,
               "position platform tilt about x, arcsec", &E::position_perpendicularity_x_rad),
      constant("position_perpendicularity_z", "arcsec", "arcsec", kArcsec, kArcsec,
               "position platform tilt about z, arcsec", &E::position_perpendicularity_z_rad),
      series("position_wobble_x", "arcsec", "arcsec", kArcsec, kArcsec,
             "position platform wobble about x, harmonics of beta', arcsec", &E::position_wobble_x_rad),
      series("position_wobble_z", "arcsec", "arcsec", kArcsec, kArcsec,
             "position platform wobble about z, harmonics of beta', arcsec", &E::position_wobble_z_rad),
      constant("position_angle_error", "arcsec", "arcsec", kArcsec, kArcsec,
               "added to the commanded beta, arcsec", &E::position_angle_error_rad),
      vector("mount_misalignment", "arcsec", "arcsec", kArcsec, kArcsec,
             "gyro mounting misalignment about I, O, S, arcsec", &E::mount_misalignment_rad),
      vector("lever_arm", "m", "m", 1.0, 1e-3,
             "gyro centre offset in position-platform axes (I, O, S at beta = 0), m", &E::lever_arm_m),
      output_delay(),
  };
}

/// The cosine and sine parts (SI) of harmonic n of `s`, summed over its terms of that harmonic.
std::pair<double, double> parts(const HarmonicSeries& s, int n) {
  double c = 0.0, si = 0.0;
  for (const HarmonicTerm& t : s.terms)
    if (t.harmonic == n) {
      c += t.amplitude * std::cos(t.phase_rad);
      si += t.amplitude * std::sin(t.phase_rad);
    }
  return {c, si};
}

std::string trimmed(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return std::string(s.substr(b, e - b + 1));
}

std::string known_names() {
  std::string out;
  for (const MachineErrorField& f : machine_error_fields())
    out += (out.empty() ? "" : ", ") + std::string(f.name) + (f.kind == K::kSeries ? ":N" : "");
  return out;
}

}  // namespace

std::string MachineErrorField::key() const {
  return kind == K::kSeries ? std::string(name) : std::string(name) + "_" + std::string(unit_suffix);
}

std::string MachineErrorField::amplitude_key() const {
  return "amplitude_" + std::string(unit_suffix);
}

const std::vector<MachineErrorField>& machine_error_fields() {
  static const std::vector<MachineErrorField> fields = make_fields();
  return fields;
}

int find_machine_error_field(std::string_view name) {
  const auto& fields = machine_error_fields();
  for (std::size_t i = 0; i < fields.size(); ++i)
    if (fields[i].name == name) return static_cast<int>(i);
  return -1;
}

std::string MachineErrorParameter::error_name() const {
  const MachineErrorField& f = info();
  if (f.kind == K::kVector)
    return std::string(f.name) + "_" +
           std::string(kVectorComponentNames[static_cast<std::size_t>(component)]);
  if (f.kind == K::kSeries) return std::string(f.name) + ":" + std::to_string(harmonic);
  return std::string(f.name);
}

std::string MachineErrorParameter::label() const {
  return error_name() + (part == HarmonicPart::kCos ? " cos" : part == HarmonicPart::kSin ? " sin" : "");
}

double MachineErrorParameter::get(const CentrifugeErrors& errors) const {
  const MachineErrorField& f = info();
  switch (f.kind) {
    case K::kConstant:
      return errors.*f.scalar;
    case K::kVector:
      return (errors.*f.vector)[component];
    case K::kSeries: {
      const auto [c, s] = parts(errors.*f.series, harmonic);
      return part == HarmonicPart::kSin ? s : c;
    }
  }
  return 0.0;
}

void MachineErrorParameter::set(CentrifugeErrors& errors, double value_si) const {
  const MachineErrorField& f = info();
  switch (f.kind) {
    case K::kConstant:
      errors.*f.scalar = value_si;
      return;
    case K::kVector:
      (errors.*f.vector)[component] = value_si;
      return;
    case K::kSeries: {
      HarmonicSeries& s = errors.*f.series;
      auto [c, si] = parts(s, harmonic);
      (part == HarmonicPart::kSin ? si : c) = value_si;
      std::erase_if(s.terms, [this](const HarmonicTerm& t) { return t.harmonic == harmonic; });
      // a*cos(n x + phi) with a = |(c, s)| >= 0, phi = atan2(s, c): the parts are c and s again.
      s.terms.push_back({harmonic, std::hypot(c, si), std::atan2(si, c)});
      return;
    }
  }
}

std::vector<std::string> split_names(std::string_view list) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    std::string item = trimmed(list.substr(begin, end - begin));
    if (!item.empty()) out.push_back(std::move(item));
    begin = end + 1;
  }
  return out;
}

std::vector<MachineErrorParameter> parse_machine_error_names(const std::vector<std::string>& names,
                                                             const std::string& source) {
  // Each name is one to three columns of the design: their number is bounded (core/limits.hpp).
  if (names.size() > limits::kEstimatedErrors)
    throw Error(source + " names " + std::to_string(names.size()) + " machine errors; at most " +
                std::to_string(limits::kEstimatedErrors) + " can be estimated.");
  std::vector<MachineErrorParameter> out;
  const auto add = [&](const MachineErrorParameter& p, const std::string& name) {
    for (const MachineErrorParameter& q : out)
      if (q.field == p.field && q.component == p.component && q.harmonic == p.harmonic && q.part == p.part)
        throw Error(source + ": " + name + " names " + p.label() + " a second time; name each error once.");
    out.push_back(p);
  };
  for (const std::string& name : names) {
    const std::size_t colon = name.find(':');
    const std::string base = name.substr(0, colon);
    int field = find_machine_error_field(base);
    int component = -1;
    if (field < 0) {
      // A vector's component: name_I, name_O, name_S.
      for (std::size_t c = 0; c < 3 && field < 0; ++c) {
        const std::string suffix = "_" + std::string(kVectorComponentNames[c]);
        if (base.size() > suffix.size() && base.ends_with(suffix)) {
          const int f = find_machine_error_field(base.substr(0, base.size() - suffix.size()));
          if (f >= 0 && machine_error_fields()[static_cast<std::size_t>(f)].kind == K::kVector) {
            field = f;
            component = static_cast<int>(c);
          }
        }
      }
    }
    if (field < 0)
      throw Error(source + ": unknown machine error '" + name + "' (expected one of " + known_names() +
                  "; a vector's component as NAME_I, NAME_O or NAME_S).");
    const MachineErrorField& f = machine_error_fields()[static_cast<std::size_t>(field)];
    MachineErrorParameter p;
    p.field = field;
    if (f.kind == K::kSeries) {
      int n = 0;
      const std::string number = colon == std::string::npos ? std::string() : name.substr(colon + 1);
      const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), n);
      if (colon == std::string::npos || ec != std::errc() || ptr != number.data() + number.size() || n < 1)
        throw Error(source + ": " + name + " is a harmonic series; name one harmonic N >= 1 of it as " +
                    base + ":N (e.g. " + base + ":2).");
      if (n > limits::kHarmonic)
        throw Error(source + ": " + name + " names harmonic " + std::to_string(n) + "; the highest is " +
                    std::to_string(limits::kHarmonic) + " (a geometric error lives in the first harmonics).");
      p.harmonic = n;
      p.part = HarmonicPart::kCos;
      add(p, name);
      p.part = HarmonicPart::kSin;
      add(p, name);
      continue;
    }
    if (colon != std::string::npos)
      throw Error(source + ": " + base + " is a constant error, not a harmonic series: name it without ':" +
                  name.substr(colon + 1) + "'.");
    if (f.kind == K::kVector && component < 0) {
      for (int c = 0; c < 3; ++c) {
        p.component = c;
        add(p, name);
      }
      continue;
    }
    p.component = std::max(component, 0);
    add(p, name);
  }
  return out;
}

}  // namespace gyrocal

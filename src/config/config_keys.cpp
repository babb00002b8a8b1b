// The keys of [centrifuge.errors] and [uncertainty], derived from the one table of machine errors, and the
// one-rate rule that the reader and the writer share (config_keys.hpp).
#include "config_keys.hpp"

namespace gyrocal::config_detail {

const std::vector<ErrorKey>& error_keys() {
  static const std::vector<ErrorKey> keys = [] {
    std::vector<ErrorKey> out;
    for (const MachineErrorField& f : machine_error_fields()) out.push_back({&f, f.key(), f.amplitude_key()});
    return out;
  }();
  return keys;
}

bool holds(ErrorKeys keys, const MachineErrorField& field) {
  if (keys == ErrorKeys::kAll) return true;
  return (field.section == MachineErrorSection::kRecord) == (keys == ErrorKeys::kRecord);
}

/// The test's first non-zero rate, which [centrifuge] rate_rad_s follows when the file gives only [test]
/// rates_rad_s; nullopt for a static test.
std::optional<double> first_spinning_rate(const std::vector<double>& rates) {
  for (const double r : rates)
    if (r != 0.0) return r;
  return std::nullopt;
}

}  // namespace gyrocal::config_detail

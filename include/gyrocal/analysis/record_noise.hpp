#pragma once
// Noise characterisation of a record (physics.md section 13, docs/noise.md): the output column of a static
// test, read as a stream into memory (8 bytes a sample), checked for even sampling, and characterised by
// characterise_noise().
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gyrocal/core/noise_terms.hpp"
#include "gyrocal/record/record_layout.hpp"

namespace gyrocal {

/// Limits of what a record must be for the Allan deviation to mean anything.
struct RecordNoiseOptions {
  /// The largest interval between two rows, in units of the record's median interval, still taken as one
  /// sample step (clock jitter). A longer one is a gap, and the Allan deviation needs evenly spaced samples.
  double max_interval_ratio = 1.5;  // default: half a sample missing is already a gap
  /// The smallest interval, likewise: shorter means rows out of step (a duplicated or a stray row).
  double min_interval_ratio = 0.5;
};

/// A record's noise: the characterisation and where it came from.
struct RecordNoise {
  NoiseCharacterisation noise;
  double sample_rate_hz = 0.0;  ///< from the median interval between rows
  std::uint64_t samples = 0;    ///< rows read
  std::string record;           ///< the record's name, for messages and the result
};

/// Reads the record at `path` and characterises its output (deg/h). `layout`: the record's layout (the
/// configuration's [record], docs/records.md; its angle columns may be absent), nullopt for gyrocal's own
/// format. Throws Error naming the file and line when the record is not valid, the sampling is uneven (a gap
/// or a stray row, with its time), or there are too few rows.
RecordNoise characterise_record_noise(const std::filesystem::path& path,
                                      const RecordNoiseOptions& options = {},
                                      const std::optional<RecordLayout>& layout = std::nullopt);

/// The same for samples held in memory (time in s, output in deg/h); `name` stands for the record in
/// messages.
RecordNoise characterise_samples_noise(const std::vector<double>& time_s,
                                       const std::vector<double>& rate_deg_h, const std::string& name,
                                       const RecordNoiseOptions& options = {});

}  // namespace gyrocal

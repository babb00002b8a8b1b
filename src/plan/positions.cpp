#include "gyrocal/plan/positions.hpp"

namespace gyrocal {

std::vector<Position> test_positions(const TestSpec& test) {
  std::vector<Position> out;
  int index = 1;
  for (double rate : test.rates_rad_s)
    for (double offset : test.counter_rate_offsets_rad_s)
      for (double beta : test.beta_rad)
        for (double gamma : rate != 0.0 || offset != 0.0 ? spinning_gammas(test) : test.gamma_rad)
          out.push_back({index++, rate, beta, gamma, offset});
  return out;
}

}  // namespace gyrocal

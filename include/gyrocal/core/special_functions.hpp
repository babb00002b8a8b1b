#pragma once
// Special functions of statistics, written once (no Boost on the machines): the regularised incomplete gamma
// and beta functions, from which the chi-square and F distributions' tail probabilities follow.

namespace gyrocal {

/// The regularised lower incomplete gamma function P(a, x) = gamma(a, x) / Gamma(a), a > 0, x >= 0 (0 for
/// x <= 0). The chi-square distribution's CDF at q with k degrees of freedom is P(k/2, q/2).
double regularized_gamma_p(double a, double x);

/// The regularised upper incomplete gamma function Q(a, x) = 1 - P(a, x), summed directly where it is small
/// (1 for x <= 0): the chi-square tail probability at q with k degrees of freedom is Q(k/2, q/2).
double regularized_gamma_q(double a, double x);

/// The regularised incomplete beta function I_x(a, b), a, b > 0 (0 for x <= 0, 1 for x >= 1). The F
/// distribution's tail: P(F(d1, d2) > f) = I_{d2/(d2 + d1 f)}(d2/2, d1/2).
double regularized_beta(double a, double b, double x);

}  // namespace gyrocal

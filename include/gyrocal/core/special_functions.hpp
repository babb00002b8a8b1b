#pragma once
// Special functions of statistics, written once (no Boost on the machines): the regularised incomplete gamma
// and beta functions, from which the chi-square, F and Student's t distributions' tail probabilities follow.
// (The chi-square quantile is core/noise_terms.hpp's chi_squared_quantile.)

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

/// The two-sided tail probability of Student's t with `dof` (> 0) degrees of freedom, P(|T| >= |t|) =
/// I_{dof/(dof + t^2)}(dof/2, 1/2): 1 at t = 0, 0 for an infinite t. NaN for a NaN t or a dof that is not
/// finite and > 0.
double student_t_two_sided_p(double t, double dof);

}  // namespace gyrocal

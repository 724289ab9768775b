// A distribution of a positive time (pre-movement times: RiMEA test 5, NIST
// TN 1822 Verif.1.1's four cases): one definition of its shape, its quantile
// (how a scenario draws from it) and its CDF (how the validation suite tests
// what a run drew), so that both read one source.
//
//   {"uniform_s": [low, high]}
//   {"gamma": {"shape": a, "scale_s": b}}         density x^(a-1) e^(-x/b) / (Gamma(a) b^a)
//   {"lognormal": {"mu": m, "sigma": s}}           ln(t / 1 s) ~ N(m, s^2)
//   {"weibull": {"shape": k, "scale_s": l}}        CDF 1 - exp(-(t/l)^k)
//
// Quantiles are computed from a uniform number by the inverse CDF (Boost.Math
// for the gamma and normal inverses): the same draws on every standard
// library, unlike <random>'s distributions.
#pragma once

#include <string>

namespace crowdrecon {

class JsonReader;

struct Distribution {
  enum class Kind { kUniform, kGamma, kLognormal, kWeibull };
  Kind kind = Kind::kUniform;
  // uniform: low, high (s); gamma, weibull: shape, scale (s); lognormal: mu, sigma.
  double a = 0.0, b = 0.0;

  // The value at probability u in [0, 1) (uniform: low + u (high - low);
  // others: u is moved off 0, where their inverse is 0 or -infinity, by the
  // caller's choice: see Quantile's use in scenario/src/premovement.cpp).
  double Quantile(double u) const;
  // P(T <= t).
  double Cdf(double t) const;
  // "gamma (shape 1.291, scale 103.9 s)".
  std::string Describe() const;
  bool IsValid(std::string* error) const;
};

// Reads one of the forms above from an object with exactly one of the keys
// uniform_s, gamma, lognormal, weibull (other keys are the caller's: it
// calls Finish). Errors name the JSON path, the value and what was expected.
Distribution ReadDistribution(const JsonReader& reader);
// True if the object holds one of the distribution's keys.
bool HasDistribution(const JsonReader& reader);

}  // namespace crowdrecon

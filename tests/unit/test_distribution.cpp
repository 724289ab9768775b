// Distributions of a time (common/distribution.hpp): quantile and CDF are
// inverses, known closed forms, the readers' errors.
#include <gtest/gtest.h>

#include <cmath>

#include "crowdrecon/common/distribution.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/json_reader.hpp"

namespace crowdrecon {
namespace {

Distribution Read(const std::string& text) {
  const JsonDocument doc = JsonDocument::Parse(text, "d.json");
  const JsonReader r = doc.Root();
  const Distribution d = ReadDistribution(r);
  r.Finish();
  return d;
}

std::string ErrorOf(const std::string& text) {
  try {
    Read(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Distribution, QuantileAndCdfAreInversesForEveryShape) {
  // NIST TN 1822 Verif.1.1's four pre-evacuation distributions.
  for (const char* text : {R"({"uniform_s": [10, 100]})", R"({"gamma": {"shape": 1.291, "scale_s": 103.901}})",
                           R"({"lognormal": {"mu": 4.586, "sigma": 0.967}})",
                           R"({"weibull": {"shape": 1.195, "scale_s": 139.285}})"}) {
    const Distribution d = Read(text);
    std::string error;
    ASSERT_TRUE(d.IsValid(&error)) << error;
    for (double u : {1e-6, 0.01, 0.25, 0.5, 0.75, 0.99, 0.999999}) {
      const double t = d.Quantile(u);
      EXPECT_GT(t, 0.0) << text;
      EXPECT_NEAR(d.Cdf(t), u, 1e-9) << text << " u " << u;
    }
  }
}

TEST(Distribution, ClosedFormsAreMet) {
  // Gamma of shape 1 is the exponential: median b ln 2.
  EXPECT_NEAR(Read(R"({"gamma": {"shape": 1, "scale_s": 50}})").Quantile(0.5), 50.0 * std::log(2.0), 1e-9);
  // Gamma of shape 2, scale 1: CDF 1 - (1 + x) e^-x.
  EXPECT_NEAR(Read(R"({"gamma": {"shape": 2, "scale_s": 1}})").Cdf(1.5), 1.0 - 2.5 * std::exp(-1.5), 1e-12);
  // The log-normal's median is e^mu; one sigma up is the 84.13 % point.
  const Distribution ln = Read(R"({"lognormal": {"mu": 4.586, "sigma": 0.967}})");
  EXPECT_NEAR(ln.Quantile(0.5), std::exp(4.586), 1e-9);
  EXPECT_NEAR(ln.Cdf(std::exp(4.586 + 0.967)), 0.8413447460685429, 1e-12);
  // Weibull: the scale is the 1 - 1/e point.
  EXPECT_NEAR(Read(R"({"weibull": {"shape": 1.195, "scale_s": 139.285}})").Cdf(139.285), 1.0 - std::exp(-1.0), 1e-12);
  // Uniform: a straight line, 0 below and 1 above.
  const Distribution u = Read(R"({"uniform_s": [10, 100]})");
  EXPECT_DOUBLE_EQ(u.Quantile(0.5), 55.0);
  EXPECT_EQ(u.Cdf(5.0), 0.0);
  EXPECT_EQ(u.Cdf(100.0), 1.0);
  EXPECT_NE(Read(R"({"gamma": {"shape": 1.291, "scale_s": 103.901}})").Describe().find("gamma (shape 1.291"),
            std::string::npos);
}

TEST(Distribution, BadDistributionsAreRefusedWithTheirPath) {
  EXPECT_NE(ErrorOf(R"({})").find("exactly one distribution"), std::string::npos);
  EXPECT_NE(ErrorOf(R"({"uniform_s": [10, 100], "weibull": {"shape": 1, "scale_s": 1}})").find("exactly one"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"uniform_s": [100, 10]})").find("/uniform_s"), std::string::npos);
  EXPECT_NE(ErrorOf(R"({"gamma": {"shape": 0, "scale_s": 1}})").find("/gamma/shape"), std::string::npos);
  EXPECT_NE(ErrorOf(R"({"gamma": {"shape": 1}})").find("scale_s"), std::string::npos);
  EXPECT_NE(ErrorOf(R"({"lognormal": {"mu": 4, "sigma": 0}})").find("/lognormal/sigma"), std::string::npos);
  EXPECT_NE(ErrorOf(R"({"weibull": {"shape": 1, "scale_s": 1, "k": 2}})").find("k"), std::string::npos);
  EXPECT_NE(ErrorOf(R"({"weibull": 3})").find("expected an object"), std::string::npos);
  // Draws the times cannot hold (issue 65, G08, K39): at 0 s or beyond any run.
  EXPECT_NE(ErrorOf(R"({"weibull": {"shape": 0.001, "scale_s": 1000000}})")
                .find("/weibull: its 1 % and 99 % quantiles are 0 and"),
            std::string::npos)
      << ErrorOf(R"({"weibull": {"shape": 0.001, "scale_s": 1000000}})");
  EXPECT_NE(ErrorOf(R"({"lognormal": {"mu": 19, "sigma": 5}})").find("expected both within [1e-9, 1e6] s"), std::string::npos);
  EXPECT_EQ(ErrorOf(R"({"weibull": {"shape": 1.5, "scale_s": 60}})"), "");  // NIST's kind of values
}

}  // namespace
}  // namespace crowdrecon

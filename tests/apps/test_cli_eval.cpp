// `vitri eval`: runs the real binary. Constraints sampled from a linear function must give back exactly
// that function and its gradient (the RBF reproduces degree-1 polynomials); bad input exits with 1 and a
// message naming the file and line; usage errors exit with 2.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace {

const std::string kDir = VITRI_TEST_WORK_DIR;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs `vitri eval ARGS`, capturing stdout and stderr; returns the exit code.
int run(const std::string& args, std::string& out, std::string& err) {
  const std::string o = kDir + "/eval_stdout.txt", e = kDir + "/eval_stderr.txt";
  const int rc = std::system((std::string(VITRI_CLI) + " eval " + args + " > " + o + " 2> " + e).c_str());
  out = slurp(o);
  err = slurp(e);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

double linear(double x, double y, double z) { return 0.5 + x + 2 * y - z; }

}  // namespace

TEST_CASE("vitri eval reproduces a linear function and its gradient", "[cli][eval]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::string input = kDir + "/eval_linear.xyzv", query = kDir + "/eval_query.xyz";
  {
    std::ofstream c(input);
    c << "# f = 0.5 + x + 2y - z sampled at random points\n";
    c.precision(17);
    for (int i = 0; i < 30; ++i) {
      const double x = u(rng), y = u(rng), z = u(rng);
      c << x << ' ' << y << ' ' << z << ' ' << linear(x, y, z) << '\n';
    }
  }
  std::vector<std::array<double, 3>> q;
  {
    std::ofstream f(query);
    f.precision(17);
    for (int i = 0; i < 12; ++i) {
      q.push_back({2 * u(rng), 2 * u(rng), 2 * u(rng)});
      f << q.back()[0] << ' ' << q.back()[1] << ' ' << q.back()[2] << '\n';
    }
  }
  std::string out, err;
  REQUIRE(run(input + " --at " + query, out, err) == 0);
  std::istringstream lines(out);
  for (const auto& p : q) {
    double f = 0, gx = 0, gy = 0, gz = 0;
    REQUIRE(static_cast<bool>(lines >> f >> gx >> gy >> gz));
    CHECK(f == Approx(linear(p[0], p[1], p[2])).margin(1e-9));
    CHECK(gx == Approx(1.0).margin(1e-8));
    CHECK(gy == Approx(2.0).margin(1e-8));
    CHECK(gz == Approx(-1.0).margin(1e-8));
  }
  double extra = 0;
  CHECK_FALSE(static_cast<bool>(lines >> extra));  // exactly one line per query point
}

TEST_CASE("vitri eval reports malformed input with file and line", "[cli][eval]") {
  const std::string input = kDir + "/eval_bad.xyzv", query = kDir + "/eval_query1.xyz";
  {
    std::ofstream c(input);
    c << "0 0 0 1\n1 0 0 2\n0 1 zero 3\n";
    std::ofstream f(query);
    f << "0 0 0\n";
  }
  std::string out, err;
  CHECK(run(input + " --at " + query, out, err) == 1);
  CHECK(err.find("eval_bad.xyzv:3") != std::string::npos);
  CHECK(out.empty());
}

TEST_CASE("vitri eval usage errors", "[cli][eval]") {
  std::string out, err;
  CHECK(run(kDir + "/does_not_exist.xyzv --at " + kDir + "/also_missing.xyz", out, err) == 1);
  CHECK(err.find("does_not_exist.xyzv") != std::string::npos);
  CHECK(run("", out, err) == 2);  // no input, no --at
}

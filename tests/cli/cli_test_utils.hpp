#pragma once
// Helpers for end-to-end tests of the strata executable: temp folders, running the program,
// reading its CSV and JSON outputs.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace strata::cli_test {

/// A fresh folder per test, removed afterwards.
class TempFolder {
 public:
  TempFolder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_path = std::filesystem::temp_directory_path() /
             ("strata_cli_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
              std::to_string(::getpid()));
    std::filesystem::remove_all(m_path);
    std::filesystem::create_directories(m_path);
  }
  ~TempFolder() { std::filesystem::remove_all(m_path); }
  const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Result of one run of the strata executable.
struct CliResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// Runs `strata <arguments>` (arguments already shell-quoted where needed) in `folder`.
inline CliResult run_strata(const std::string& arguments, const std::filesystem::path& folder) {
  const std::filesystem::path out = folder / "stdout.txt";
  const std::filesystem::path err = folder / "stderr.txt";
  const std::string command = "cd '" + folder.string() + "' && '" + STRATA_CLI_PATH + "' " +
                              arguments + " > '" + out.string() + "' 2> '" + err.string() + "'";
  const int status = std::system(command.c_str());
  CliResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = read_text(out);
  result.err = read_text(err);
  return result;
}

/// A CSV file: header and rows of numbers.
struct Csv {
  std::string header;
  std::vector<std::vector<double>> rows;
};

inline Csv read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  Csv csv;
  std::getline(in, csv.header);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ','))
      row.push_back(std::stod(field));
    csv.rows.push_back(row);
  }
  return csv;
}

/// The largest probe-displacement difference of the run in folder `run` to the one in
/// `reference` (their probes.csv, row for row) over every frame and probe, relative to the
/// largest reference displacement: the error measure of `hierarchy.tolerance`.
inline double probe_error(const std::filesystem::path& run,
                          const std::filesystem::path& reference) {
  const Csv a = read_csv(run / "probes.csv");
  const Csv b = read_csv(reference / "probes.csv");
  EXPECT_EQ(a.rows.size(), b.rows.size()) << run << " against " << reference;
  double difference = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < std::min(a.rows.size(), b.rows.size()); ++i) {
    double d = 0.0, s = 0.0;
    for (int k = 5; k < 8; ++k) {
      d += (a.rows[i][k] - b.rows[i][k]) * (a.rows[i][k] - b.rows[i][k]);
      s += b.rows[i][k] * b.rows[i][k];
    }
    difference = std::max(difference, std::sqrt(d));
    scale = std::max(scale, std::sqrt(s));
  }
  return difference / scale;
}

inline nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace strata::cli_test

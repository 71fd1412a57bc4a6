// The malformed-checkpoint corpus (tests/data/bad_checkpoints/, made by make_corpus.py): resuming
// from any of its files is an InputError whose message starts with the file's path and gives the
// reason expected.txt names for it — never a crash, never another exception. (When the format
// changes, regenerate the corpus: a stale file would be refused for the wrong reason.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "hilldem/core/error.hpp"
#include "hilldem/io/runner.hpp"

namespace {

namespace fs = std::filesystem;

fs::path corpus_dir() { return fs::path(HILLDEM_SOURCE_DIR) / "tests" / "data" / "bad_checkpoints"; }

std::vector<std::string> corpus() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(corpus_dir()))
    if (e.path().extension() == ".hdc") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::map<std::string, std::string> expected_reasons() {
  std::map<std::string, std::string> m;
  std::ifstream in(corpus_dir() / "expected.txt");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(": ");
    if (colon != std::string::npos) m[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return m;
}

TEST(BadCheckpointCorpus, HasAtLeast30FilesEachWithItsReason) {
  EXPECT_GE(corpus().size(), 30u);
  const auto reasons = expected_reasons();
  for (const std::string& f : corpus()) EXPECT_TRUE(reasons.count(f)) << f << " has no line in expected.txt";
}

class BadCheckpoint : public ::testing::TestWithParam<std::string> {};

TEST_P(BadCheckpoint, ResumeRefusesItNamingTheFile) {
  const std::string path = (corpus_dir() / GetParam()).string();
  const fs::path out = fs::temp_directory_path() / ("hilldem_badckpt_" + std::to_string(::getpid()));
  try {
    hilldem::Scenario sc;
    hilldem::RunOptions o;
    o.quiet = true;
    o.output_dir = out.string();
    std::ostringstream log;
    hilldem::resume_scenario(path, sc, o, log);
    ADD_FAILURE() << path << " was resumed";
  } catch (const hilldem::InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
    const std::string reason = expected_reasons()[GetParam()];
    EXPECT_FALSE(reason.empty());
    EXPECT_NE(m.find(reason), std::string::npos) << "expected the reason '" << reason << "', got: " << m;
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": expected hilldem::InputError, got: " << e.what();
  }
  std::error_code ec;
  fs::remove_all(out, ec);
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param.substr(0, info.param.size() - 4);
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadCheckpoint, ::testing::ValuesIn(corpus()), test_name);

}  // namespace

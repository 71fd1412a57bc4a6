// The malformed-input corpus: every file under tests/data/bad/ must be refused with a
// hilldem::InputError that names the file (never another exception, never a crash).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

#include "hilldem/core/error.hpp"
#include "hilldem/io/scenario.hpp"

namespace {

namespace fs = std::filesystem;

fs::path corpus_dir() { return fs::path(HILLDEM_SOURCE_DIR) / "tests" / "data" / "bad"; }

std::vector<std::string> corpus() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(corpus_dir(), ec))
    if (e.is_regular_file() && e.path().extension() == ".toml") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param.substr(0, info.param.size() - 5);  // drop ".toml"
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

TEST(BadInputCorpus, HasAtLeast25Files) { EXPECT_GE(corpus().size(), 25u) << corpus_dir(); }

class BadInputFile : public ::testing::TestWithParam<std::string> {};

TEST_P(BadInputFile, Refused) {
  const std::string path = (corpus_dir() / GetParam()).string();
  try {
    hilldem::load_scenario_file(path);
    ADD_FAILURE() << path << " loaded: it is valid, or the reader misses what is wrong with it";
  } catch (const hilldem::InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << "the message does not start with the file name: " << m;
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": expected hilldem::InputError, got another exception: " << e.what();
  } catch (...) {
    ADD_FAILURE() << path << ": expected hilldem::InputError, got a non-standard exception";
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInputFile, ::testing::ValuesIn(corpus()), test_name);

}  // namespace

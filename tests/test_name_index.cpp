// detail::NameIndex (phiq/name_index.hpp): every name stored is found with its index and no other, whether it went
// to a stem's run ("x17") or to the hash table ("x017", "theta", a number far beyond its run), in any order.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "phiq/name_index.hpp"

namespace phiq {
namespace {

// The names and an index over them, as Model keeps them: name k is names[k].
struct NameIndexFixture {
  std::vector<std::string> names;
  detail::NameIndex index;
  bool add(const std::string& name) {
    const auto of = [this](Index k) -> const std::string& { return names[static_cast<std::size_t>(k)]; };
    if (!index.insert(name, static_cast<Index>(names.size()), of)) return false;
    names.push_back(name);
    return true;
  }
  Index find(const std::string& name) const {
    return index.find(name, [this](Index k) -> const std::string& { return names[static_cast<std::size_t>(k)]; });
  }
};

TEST(NameIndex, NumberedNamesWithLeadingZerosOrBeyondTheirRunAreDistinctNames) {
  NameIndexFixture t;
  const std::vector<std::string> names = {"x1", "x01",        "x001",        "x0",           "x00",   "1",  "01", "",
                                          "x",  "x999999999", "x1000000000", "x12345678901", "theta", "x2", "y1"};
  for (const std::string& n : names) EXPECT_TRUE(t.add(n)) << n;
  for (std::size_t k = 0; k < names.size(); ++k) EXPECT_EQ(t.find(names[k]), static_cast<Index>(k)) << names[k];
  for (const std::string& n : names) EXPECT_FALSE(t.add(n)) << n;  // each one a duplicate now
  for (const char* n : {"x3", "x02", "y0", "z1", "x99999999", "theta1", "the"}) EXPECT_EQ(t.find(n), -1) << n;
}

TEST(NameIndex, FamiliesInAnyOrderAreFoundAndRefusedTwice) {
  NameIndexFixture t;
  std::vector<std::string> names;
  for (int i = 0; i < 3000; ++i) names.push_back("P" + std::to_string(i)), names.push_back("c" + std::to_string(i));
  std::mt19937 rng(7);
  std::shuffle(names.begin(), names.end(), rng);  // numbers far beyond a run's count first: some go to the table
  for (int i = 2999; i >= 0; --i) names.push_back("Q" + std::to_string(i));  // a family read backwards
  for (const std::string& n : names) ASSERT_TRUE(t.add(n)) << n;
  for (std::size_t k = 0; k < names.size(); ++k) ASSERT_EQ(t.find(names[k]), static_cast<Index>(k)) << names[k];
  for (const std::string& n : names) ASSERT_FALSE(t.add(n)) << n;
  EXPECT_EQ(t.find("P3000"), -1);
  EXPECT_EQ(t.find("Q3000"), -1);
  t.index.clear();
  EXPECT_EQ(t.find("P0"), -1);
}

}  // namespace
}  // namespace phiq

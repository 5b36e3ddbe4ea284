// A mistyped hsactl command is answered with the nearest one, and only when it is near.
#include "tools/hsactl/suggest.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hsa::ctl {
namespace {

const std::vector<std::string> kCommands{"enable", "disable", "reset", "status", "drivers", "axes", "move", "mode"};

TEST(Suggest, EditDistanceCountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(edit_distance("status", "status"), 0u);
  EXPECT_EQ(edit_distance("stauts", "status"), 2u);  // a transposition is two edits
  EXPECT_EQ(edit_distance("enabel", "enable"), 2u);
  EXPECT_EQ(edit_distance("rest", "reset"), 1u);
  EXPECT_EQ(edit_distance("", "axes"), 4u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
}

TEST(Suggest, NearestNamesTheCommandMeant) {
  EXPECT_EQ(nearest("stauts", kCommands), "status");
  EXPECT_EQ(nearest("enabel", kCommands), "enable");
  EXPECT_EQ(nearest("rest", kCommands), "reset");
  EXPECT_EQ(nearest("driver", kCommands), "drivers");
}

TEST(Suggest, NothingWhenNoCommandIsNear) {
  EXPECT_EQ(nearest("launch", kCommands), std::nullopt);
  EXPECT_EQ(nearest("xy", kCommands), std::nullopt);  // a two-letter word is never near enough
  EXPECT_EQ(nearest("status", std::vector<std::string>{}), std::nullopt);
}

TEST(Suggest, UnknownCommandAsksAboutTheNearestOnlyWhenThereIsOne) {
  EXPECT_EQ(unknown_command("stauts", kCommands), "unknown command 'stauts'; did you mean 'status'?");
  EXPECT_EQ(unknown_command("launch", kCommands), "unknown command 'launch'");
}

}  // namespace
}  // namespace hsa::ctl

// Settings errors name the key and what was expected.
#include "drivers/settings.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <string>

namespace hsa::io {
namespace {

using ::testing::HasSubstr;

std::string error_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const SettingsError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SettingsError thrown";
  return {};
}

TEST(Settings, ReadsTypedValuesAndFallsBack) {
  const toml::table t = toml::parse(R"(mass = 12
step = 1e-4
seed = 7
on = true
valve = "servo")");
  const Settings s(t);
  EXPECT_EQ(s.number("mass", 0.0), 12.0);  // an integer is a number
  EXPECT_EQ(s.positive_number("step", 1.0), 1e-4);
  EXPECT_EQ(s.integer("seed", 0), 7);
  EXPECT_TRUE(s.boolean("on", false));
  EXPECT_EQ(s.choice("valve", {"servo", "proportional"}, "proportional"), "servo");
  EXPECT_EQ(s.number("absent", 3.5), 3.5);
  EXPECT_EQ(s.string("absent", "x"), "x");
}

TEST(Settings, ErrorsNameTheKeyTheExpectationAndTheValue) {
  const toml::table t = toml::parse(R"(valve = "foo"
mass = "heavy"
step = -1
seed = 1.5)");
  const Settings s(t);
  EXPECT_EQ(error_of([&] { (void)s.choice("valve", {"servo", "proportional"}, "servo"); }),
            R"(key 'valve' must be "servo" or "proportional", got "foo")");
  EXPECT_EQ(error_of([&] { (void)s.number("mass", 0); }),
            R"(key 'mass' must be a finite number, got "heavy")");
  EXPECT_EQ(error_of([&] { (void)s.positive_number("step", 1); }),
            "key 'step' must be a positive number, got -1");
  EXPECT_EQ(error_of([&] { (void)s.integer("seed", 0); }),
            "key 'seed' must be an integer, got 1.5");
}

// NaN and infinity are numbers to TOML, but no plugin setting means either: a load of nan kg.
TEST(Settings, NumbersMustBeFinite) {
  const toml::table t = toml::parse("a = nan\nb = inf\nc = -inf\nd = 2.5\n");
  const Settings s(t);
  EXPECT_EQ(error_of([&] { (void)s.number("a", 0); }), "key 'a' must be a finite number, got nan");
  EXPECT_EQ(error_of([&] { (void)s.number("b", 0); }), "key 'b' must be a finite number, got inf");
  EXPECT_EQ(error_of([&] { (void)s.number("c", 0); }), "key 'c' must be a finite number, got -inf");
  EXPECT_EQ(s.number("d", 0), 2.5);
}

TEST(Settings, NestedTablesCarryTheirPath) {
  const toml::table t = toml::parse("at_s = true");
  const Settings s(t, "events[2].");
  EXPECT_EQ(error_of([&] { (void)s.number("at_s", 0); }),
            "key 'events[2].at_s' must be a finite number, got true");
}

TEST(Settings, UnknownKeysAreRejected) {
  const toml::table t = toml::parse("valve = \"servo\"\nlaod_kg = 3");
  const Settings s(t);
  EXPECT_THAT(error_of([&] { s.reject_unknown_keys({"valve", "load_kg"}); }),
              HasSubstr("unknown key 'laod_kg' (known keys: valve, load_kg)"));
}

}  // namespace
}  // namespace hsa::io

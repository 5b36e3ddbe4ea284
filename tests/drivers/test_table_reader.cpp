// The configuration's one reader: typed values, fallbacks, and errors that name the file, line,
// column, key path, what was expected and what was found.
#include "drivers/table_reader.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/config_error.hpp"

namespace hsa::io {
namespace {

using ::testing::HasSubstr;

std::string error_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ConfigError thrown";
  return {};
}

TEST(TableReader, ReadsTypedValuesAndFallsBack) {
  const toml::table t = toml::parse(R"(mass = 12
step = 1e-4
seed = 7
on = true
valve = "servo")");
  const TableReader s = TableReader::of(t);
  EXPECT_EQ(s.number("mass", NumberRange::any()), 12.0);  // an integer is a number
  EXPECT_EQ(s.number("step", NumberRange::positive(), 1.0), 1e-4);
  EXPECT_EQ(s.integer("seed", 0, 10), 7);
  EXPECT_TRUE(s.boolean("on", false));
  EXPECT_EQ(s.choice("valve", {"servo", "proportional"}, "proportional"), "servo");
  EXPECT_EQ(s.number("absent", NumberRange::any(), 3.5), 3.5);
  EXPECT_EQ(s.string("absent", "a name", "x"), "x");
}

TEST(TableReader, ErrorsNameThePlaceTheKeyTheExpectationAndTheValue) {
  const toml::table t = toml::parse(R"(valve = "foo"
mass = "heavy"
step = -1
seed = 1.5)",
                                    std::string_view("rig.toml"));
  const TableReader s = TableReader::of(t);
  EXPECT_EQ(error_of([&] { (void)s.choice("valve", {"servo", "proportional"}, "servo"); }),
            R"(rig.toml:1:9: valve: expected "servo" or "proportional", got "foo")");
  EXPECT_EQ(error_of([&] { (void)s.number("mass", NumberRange::any()); }),
            R"(rig.toml:2:8: mass: expected a finite number, got "heavy")");
  EXPECT_EQ(error_of([&] { (void)s.number("step", NumberRange::positive(), 1.0); }),
            "rig.toml:3:8: step: expected a finite number > 0, got -1");
  EXPECT_EQ(error_of([&] { (void)s.integer("seed", 0, 9); }),
            "rig.toml:4:8: seed: expected an integer in [0, 9], got 1.5");
  EXPECT_EQ(error_of([&] { (void)s.boolean("on"); }),
            "rig.toml:1:1: on: required key is missing, expected true or false");
}

// A table built in code has no file to name; the key and the expectation still come first.
TEST(TableReader, ATableWithoutASourceIsNamedByItsKeysAlone) {
  const toml::table t = toml::parse("valve = 3");
  EXPECT_EQ(error_of([&] { (void)TableReader::of(t).string("valve", "a valve kind"); }),
            "valve: expected a valve kind, got 3");
}

// NaN and infinity are numbers to TOML, but no setting means either: a load of nan kg.
TEST(TableReader, NumbersMustBeFinite) {
  const toml::table t = toml::parse("a = nan\nb = inf\nc = -inf\nd = 2.5\n");
  const TableReader s = TableReader::of(t);
  EXPECT_EQ(error_of([&] { (void)s.number("a", NumberRange::any()); }), "a: expected a finite number, got nan");
  EXPECT_EQ(error_of([&] { (void)s.number("b", NumberRange::any()); }), "b: expected a finite number, got inf");
  EXPECT_EQ(error_of([&] { (void)s.number("c", NumberRange::any()); }), "c: expected a finite number, got -inf");
  EXPECT_EQ(s.number("d", NumberRange::any()), 2.5);
}

TEST(TableReader, NestedTablesCarryTheirPath) {
  const toml::table t = toml::parse("[[events]]\nat_s = 1\n[[events]]\nat_s = true\n", std::string_view("rig.toml"));
  const std::vector<TableReader> events = TableReader::of(t).tables("events");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].number("at_s", NumberRange::any()), 1.0);
  EXPECT_EQ(error_of([&] { (void)events[1].number("at_s", NumberRange::any()); }),
            "rig.toml:4:8: events[1].at_s: expected a finite number, got true");
}

TEST(TableReader, UnknownKeysAreRejected) {
  const toml::table t = toml::parse("valve = \"servo\"\nlaod_kg = 3", std::string_view("rig.toml"));
  EXPECT_EQ(error_of([&] { TableReader::of(t).reject_unknown_keys({"valve", "load_kg"}); }),
            "rig.toml:2:1: laod_kg: unknown key, expected one of: valve, load_kg");
}

TEST(TableReader, DurationsAreSecondsRoundedToNanosecondsAndAtLeastAMicrosecond) {
  const toml::table t = toml::parse("poll_s = 0.0025\ntiny_s = 1e-7\n");
  const TableReader s = TableReader::of(t);
  EXPECT_EQ(s.duration("poll_s", NumberRange::positive()), std::chrono::microseconds(2500));
  EXPECT_EQ(s.duration("absent_s", NumberRange::positive(), 0.1), std::chrono::milliseconds(100));
  EXPECT_THAT(error_of([&] { (void)s.duration("tiny_s", NumberRange::positive()); }),
              HasSubstr("tiny_s: expected a finite number > 0 of at least 1 µs, got 1e-07"));
}

}  // namespace
}  // namespace hsa::io

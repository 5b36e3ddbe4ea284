// hsa-analyze's --json output: a JSON list with one object per line, so that a script can read it
// whole and a person can still read it by row. Numbers that are not finite (an unstable loop has no
// margin) are written as null, the JSON library's rule.
#pragma once

#include <cstdio>

#include <nlohmann/json.hpp>

namespace hsa::analyze {

class JsonList {
 public:
  void add(const nlohmann::ordered_json& object) {
    std::printf("%s  %s", first_ ? "[\n" : ",\n", object.dump().c_str());
    first_ = false;
  }
  void close() { std::printf("%s]\n", first_ ? "[" : "\n"); }

 private:
  bool first_ = true;
};

}  // namespace hsa::analyze

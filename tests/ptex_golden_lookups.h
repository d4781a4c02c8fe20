// The Ptex library's filter values for the sample files (tests/assets/ptex/golden_filters/, written
// by tests/ptex_golden/generate_golden.cpp): every filter seamcl implements, near edges, corners of
// every valence the file has, resolution changes and in the interior. Read by the twin's test and
// the kernel's test alike, so that both are held to the same values.
#pragma once
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>

#include "ptex_test_writer.h"

namespace seamcl_tests {

struct PtexGoldenLookup {
  PtexFilterQuery query{};
  std::vector<double> value;  // the library's, one per channel, on the scale of the file (0..1 for integers)
  std::string filter;         // "bicubic s=1" where the sharpness matters
  std::string where;          // interior, edge, corner-valence-5, resolution-change, ...
};

inline int ptex_golden_filter_code(const std::string& name) {
  if (name == "point") return SEAMCL_PTEX_POINT;
  if (name == "bilinear") return SEAMCL_PTEX_BILINEAR;
  if (name == "box") return SEAMCL_PTEX_BOX;
  if (name == "gaussian") return SEAMCL_PTEX_GAUSSIAN;
  if (name == "bicubic") return SEAMCL_PTEX_BICUBIC;
  throw std::runtime_error("a golden filter the tests do not know: " + name);
}

inline std::vector<PtexGoldenLookup> ptex_golden_filter_lookups(const std::string& name) {
  const std::string path = ptex_assets_dir() + "/golden_filters/" + name + ".json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  const nlohmann::json g = nlohmann::json::parse(in);
  std::vector<PtexGoldenLookup> out;
  for (const nlohmann::json& e : g.at("filtered")) {
    PtexGoldenLookup l;
    l.query.face = e.at("face").get<int>();
    l.query.filter = ptex_golden_filter_code(e.at("filter").get<std::string>());
    l.query.u = e.at("u").get<float>();
    l.query.v = e.at("v").get<float>();
    l.query.uw = e.at("uw").get<float>();
    l.query.vw = e.at("vw").get<float>();
    l.filter = e.at("filter").get<std::string>();
    if (e.contains("sharpness")) {
      l.query.sharpness = e.at("sharpness").get<float>();
      char s[32];
      std::snprintf(s, sizeof s, " s=%g", l.query.sharpness);
      l.filter += s;
    }
    l.where = e.value("where", "");
    l.value = e.at("value").get<std::vector<double>>();
    out.push_back(l);
  }
  return out;
}

// Largest |got - library| per filter over one file; reports the worst lookup of each filter and
// how many exceed the tolerance, so one failure message names what to look at.
class PtexGoldenTally {
 public:
  PtexGoldenTally(std::string file, double tolerance) : file_(std::move(file)), tolerance_(tolerance) {}

  void add(const PtexGoldenLookup& l, const float* got, int channels) {
    double difference = 0.0;
    int worst_channel = 0;
    for (int c = 0; c < channels; ++c) {
      const double d = std::fabs(static_cast<double>(got[c]) - l.value[static_cast<size_t>(c)]);
      if (d > difference) difference = d, worst_channel = c;
    }
    Worst& w = worst_[l.filter];
    w.lookups++;
    if (!(difference <= tolerance_)) w.over++;
    if (!(difference <= w.difference)) {
      w.difference = difference;
      char s[256];
      std::snprintf(s, sizeof s, "face %d at (%.9g, %.9g) widths %.9g x %.9g, %s, channel %d: %.7g vs the library's %.7g",
                    l.query.face, l.query.u, l.query.v, l.query.uw, l.query.vw, l.where.c_str(), worst_channel,
                    static_cast<double>(got[worst_channel]), l.value[static_cast<size_t>(worst_channel)]);
      w.lookup = s;
    }
  }

  // One line per filter: "[ptex golden filters] <file> <filter>: largest difference ...".
  void print(const std::string& who) const {
    for (const auto& [filter, w] : worst_)
      std::cout << "[ptex golden filters] " << who << " " << file_ << " " << filter << ": largest difference "
                << w.difference << " over " << w.lookups << " lookups\n";
  }

  // Filters with lookups over the tolerance, with their worst lookup; empty when all match.
  std::string failures() const {
    std::string out;
    for (const auto& [filter, w] : worst_)
      if (w.over > 0)
        out += file_ + " " + filter + ": " + std::to_string(w.over) + " of " + std::to_string(w.lookups) +
               " lookups differ by more than the tolerance; worst " + w.lookup + "\n";
    return out;
  }

  int lookups() const {
    int n = 0;
    for (const auto& entry : worst_) n += entry.second.lookups;
    return n;
  }

 private:
  struct Worst {
    double difference = 0.0;
    int lookups = 0, over = 0;
    std::string lookup;
  };
  std::string file_;
  double tolerance_;
  std::map<std::string, Worst> worst_;
};

}  // namespace seamcl_tests

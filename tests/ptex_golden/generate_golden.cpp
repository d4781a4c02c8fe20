// Writes the Ptex library's own filter values for a .ptx file as JSON: the oracle
// tests/test_ptex_filter*.cpp compare seamcl's twin and kernel to. Built by hand against a Ptex
// build (see README.md beside this file), never by the project.
//
//   generate_golden <file.ptx> <lookups per filter> <seed> [fixed lookups] > out.json
//
// The optional file of fixed lookups adds, after the random ones, lookups a random set is unlikely
// to hit, one per line: `filter sharpness face u v uw vw where` (filter as the output names it,
// sharpness ignored but for bicubic, u..vw as %.9g prints them, so that they read back exactly).
// Every filter seamcl implements (point, bilinear, box, gaussian, bicubic at sharpness 0 and 1)
// gets the same number of lookups, spread over places where the filters differ most: interior
// points, points within a couple of kernel widths of an edge, of a corner (sorted by the corner's
// valence so that rare valences are not drowned by common ones), and of an edge whose neighbour
// has another resolution. Widths run from about a texel to a whole face.
#include <Ptexture.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

namespace {

// A generator whose stream does not depend on the standard library's distributions, so the same
// seed gives the same lookups with any compiler.
struct Random {
  uint64_t state;
  explicit Random(uint64_t seed) : state(seed * 0x9E3779B97F4A7C15ull + 1) {}
  uint32_t next() {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return static_cast<uint32_t>(state >> 32);
  }
  float unit() { return static_cast<float>(next() >> 8) * (1.0f / 16777216.0f); }  // [0, 1)
  int below(int n) { return static_cast<int>(next() % static_cast<uint32_t>(n)); }
};

struct Corner {
  int face, edge;  // the corner where `edge` starts (counter-clockwise)
  int valence;     // faces around the vertex; 0 when the walk reaches a boundary
};

struct Filter {
  const char* name;
  PtexFilter::FilterType type;
  float sharpness;
  bool has_sharpness;
};

// (u, v) of the corner at the start of each edge: bottom, right, top, left.
const float kCornerU[4] = {0.0f, 1.0f, 1.0f, 0.0f};
const float kCornerV[4] = {0.0f, 0.0f, 1.0f, 1.0f};

int corner_valence(PtexTexture* tx, int face, int edge) {
  int f = face, e = edge;
  for (int count = 1; count < 64; ++count) {
    const Ptex::FaceInfo& info = tx->getFaceInfo(f);
    const int next = info.adjface(e);
    if (next < 0) return 0;
    e = (info.adjedge(e) + 1) % 4;
    f = next;
    if (f == face && e == edge) return count;
  }
  return 0;
}

// A point within `reach` of the given side of the face (0 and 1 themselves included now and then).
float near_side(Random& r, bool high, float reach) {
  const int pick = r.below(8);
  const float d = pick == 0 ? 0.0f : pick == 1 ? 1e-4f : r.unit() * std::min(reach, 0.5f);
  return high ? 1.0f - d : d;
}

}  // namespace

// One lookup's entry of "filtered", evaluated by pf.
void write_lookup(PtexFilter* pf, const Filter& filter, int face, float u, float v, float uw, float vw,
                  const std::string& where, int channels, bool& first) {
  std::vector<float> value(static_cast<size_t>(channels));
  pf->eval(value.data(), 0, channels, face, u, v, uw, 0.0f, 0.0f, vw);
  std::printf("%s\n  {\"filter\": \"%s\", ", first ? "" : ",", filter.name);
  if (filter.has_sharpness) std::printf("\"sharpness\": %.9g, ", filter.sharpness);
  std::printf("\"face\": %d, \"u\": %.9g, \"v\": %.9g, \"uw\": %.9g, \"vw\": %.9g, \"where\": \"%s\", \"value\": [",
              face, u, v, uw, vw, where.c_str());
  for (int c = 0; c < channels; ++c) std::printf("%s%.9g", c ? ", " : "", value[static_cast<size_t>(c)]);
  std::printf("]}");
  first = false;
}

int main(int argc, char** argv) {
  if (argc != 4 && argc != 5) {
    std::fprintf(stderr, "usage: %s file.ptx lookups-per-filter seed [fixed-lookups.txt]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  const int per_filter = std::atoi(argv[2]);
  Random r(std::strtoull(argv[3], nullptr, 10));

  Ptex::String error;
  PtexTexture* tx = PtexTexture::open(path.c_str(), error);
  if (!tx) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  if (tx->meshType() != Ptex::mt_quad) {
    std::fprintf(stderr, "%s: only quad meshes\n", path.c_str());
    return 1;
  }
  const int faces = tx->numFaces();
  const int channels = tx->numChannels();

  std::map<int, std::vector<Corner>> by_valence;
  std::vector<std::pair<int, int>> res_change_edges;  // (face, edge)
  for (int f = 0; f < faces; ++f) {
    const Ptex::FaceInfo& info = tx->getFaceInfo(f);
    for (int e = 0; e < 4; ++e) {
      const int v = corner_valence(tx, f, e);
      by_valence[v].push_back({f, e, v});
      const int a = info.adjface(e);
      if (a >= 0) {
        const Ptex::Res& mine = info.res;
        const Ptex::Res& theirs = tx->getFaceInfo(a).res;
        // Resolution along and across the shared edge, in the neighbour's orientation.
        const bool turned = (e & 1) != (info.adjedge(e) & 1);
        const int ou = turned ? theirs.vlog2 : theirs.ulog2, ov = turned ? theirs.ulog2 : theirs.vlog2;
        if (ou != mine.ulog2 || ov != mine.vlog2) res_change_edges.push_back({f, e});
      }
    }
  }
  std::vector<int> valences;
  for (const auto& entry : by_valence) valences.push_back(entry.first);

  const Filter filters[] = {
      {"point", PtexFilter::f_point, 0.0f, false},        {"bilinear", PtexFilter::f_bilinear, 0.0f, false},
      {"box", PtexFilter::f_box, 0.0f, false},            {"gaussian", PtexFilter::f_gaussian, 0.0f, false},
      {"bicubic", PtexFilter::f_bicubic, 0.0f, true},     {"bicubic", PtexFilter::f_bicubic, 1.0f, true},
  };

  std::printf("{\"file\": \"%s\", \"written_by\": \"the Ptex library (PtexFilter::eval), tests/ptex_golden/generate_golden.cpp\",\n",
              path.substr(path.find_last_of('/') + 1).c_str());
  std::printf(" \"seed\": %s, \"lookups_per_filter\": %d, \"channels\": %d,\n \"filtered\": [", argv[3], per_filter, channels);
  bool first = true;
  for (const Filter& filter : filters) {
    PtexFilter::Options options(filter.type, false, filter.sharpness);
    PtexFilter* pf = PtexFilter::getFilter(tx, options);
    for (int i = 0; i < per_filter; ++i) {
      // interior, edge, corner, resolution change
      int place = i % 10 < 2 ? 0 : i % 10 < 5 ? 1 : i % 10 < 8 ? 2 : 3;
      if (place == 3 && res_change_edges.empty()) place = 1;
      int face = r.below(faces);
      std::string where = "interior";
      const Ptex::Res* res = &tx->getFaceInfo(face).res;
      auto pick_width = [&](int log2) {
        // About a texel (a little under, which the filters clamp) to a whole face.
        return std::exp2(-(static_cast<float>(log2) + 0.5f) * r.unit());
      };
      float uw = 0, vw = 0, u = 0, v = 0;
      if (place == 2) {
        const std::vector<Corner>& group = by_valence[valences[static_cast<size_t>(i / 10) % valences.size()]];
        const Corner& c = group[static_cast<size_t>(r.below(static_cast<int>(group.size())))];
        face = c.face;
        res = &tx->getFaceInfo(face).res;
        where = c.valence == 0 ? "corner-boundary" : "corner-valence-" + std::to_string(c.valence);
        uw = pick_width(res->ulog2);
        vw = i % 3 == 0 ? uw : pick_width(res->vlog2);
        u = near_side(r, kCornerU[c.edge] > 0.5f, 2.0f * std::max(uw, 1.0f / static_cast<float>(res->u())));
        v = near_side(r, kCornerV[c.edge] > 0.5f, 2.0f * std::max(vw, 1.0f / static_cast<float>(res->v())));
      } else {
        int edge = r.below(4);
        if (place == 3) {
          const std::pair<int, int>& fe = res_change_edges[static_cast<size_t>(r.below(static_cast<int>(res_change_edges.size())))];
          face = fe.first;
          edge = fe.second;
          res = &tx->getFaceInfo(face).res;
          where = "resolution-change";
        } else if (place == 1) {
          where = tx->getFaceInfo(face).adjface(edge) < 0 ? "boundary-edge" : "edge";
        }
        uw = pick_width(res->ulog2);
        vw = i % 3 == 0 ? uw : pick_width(res->vlog2);
        u = r.unit();
        v = r.unit();
        if (place != 0) {
          const float reach_u = 2.0f * std::max(uw, 1.0f / static_cast<float>(res->u()));
          const float reach_v = 2.0f * std::max(vw, 1.0f / static_cast<float>(res->v()));
          if (edge == 0) v = near_side(r, false, reach_v);
          if (edge == 1) u = near_side(r, true, reach_u);
          if (edge == 2) v = near_side(r, true, reach_v);
          if (edge == 3) u = near_side(r, false, reach_u);
        }
      }
      write_lookup(pf, filter, face, u, v, uw, vw, where, channels, first);
    }
    pf->release();
  }
  if (argc == 5) {
    std::FILE* fixed = std::fopen(argv[4], "r");
    if (!fixed) {
      std::fprintf(stderr, "%s: cannot read\n", argv[4]);
      return 1;
    }
    char name[32], where[64];
    float sharpness, u, v, uw, vw;
    int face;
    while (std::fscanf(fixed, "%31s %f %d %f %f %f %f %63s", name, &sharpness, &face, &u, &v, &uw, &vw, where) == 8) {
      const Filter* filter = nullptr;
      for (const Filter& f : filters)
        if (std::string(f.name) == name && (!f.has_sharpness || f.sharpness == sharpness)) filter = &f;
      if (!filter || face < 0 || face >= faces) {
        std::fprintf(stderr, "%s: no filter %s at sharpness %g, or no face %d\n", argv[4], name, sharpness, face);
        return 1;
      }
      PtexFilter* pf = PtexFilter::getFilter(tx, PtexFilter::Options(filter->type, false, filter->sharpness));
      write_lookup(pf, *filter, face, u, v, uw, vw, where, channels, first);
      pf->release();
    }
    const bool whole = std::feof(fixed) != 0;
    std::fclose(fixed);
    if (!whole) {
      std::fprintf(stderr, "%s: a line is not `filter sharpness face u v uw vw where`\n", argv[4]);
      return 1;
    }
  }
  std::printf("\n ]}\n");
  tx->release();
  return 0;
}

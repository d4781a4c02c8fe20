// What the .ptx reader decoded, as JSON (`seamcl ptx info`, `seamcl ptx dump`): the header, the
// metadata, per face its resolution, flags, adjacency and constant value (the 1x1 level), and the
// texels of one face at one level. Values are as the Ptex library's getPixel returns them: integer
// types divided by their maximum, channels in the file's order.
#pragma once
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/options/option_table.h>

namespace seamcl {

nlohmann::json ptex_info_json(const PtexStored& stored);

// `ptx dump`'s options: face, level.
const OptionTable& ptex_dump_option_table();

// Face `face` at level `level` (each side halved `level` times; 0 when left out): the stored
// level where the file holds it, else the Ptex library's own reduction of it. InputError("face")
// or InputError("level") for values out of range.
nlohmann::json ptex_dump_json(const PtexStored& stored, int face, std::optional<int> level);
// The same from a request of the table's keys (face required); InputError naming the key.
nlohmann::json ptex_dump_json(const PtexStored& stored, const nlohmann::json& request);

}  // namespace seamcl

// The JSON a cell is configured with: a transform file and cell.json.
#include "client/cell/cell_config.h"
#include "core/io/io_transform.h"
#include "fuzz/fuzz_target.h"

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_transform_json)
SURFINSPECT_FUZZ_TARGET(transform_json) {
  (void)surfinspect::ParseTransformJson(std::string(bytes), "fuzz.json");
}
#endif

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_cell_json)
SURFINSPECT_FUZZ_TARGET(cell_json) {
  // ReadCellConfig resolves the paths inside but opens none of them.
  (void)surfinspect::client::ReadCellConfig(surfinspect::fuzz::WriteScratchFile(bytes, "json"));
}
#endif

// `surfinspect errormap` as a library: reads a scanned cloud (world frame),
// a CAD mesh (part frame) and optionally the part's pose and an inspection
// plan; finds the signed error map (paper §IV) in-process or on surfinspectd;
// judges the plan; writes the files asked for through the part-file
// catalogue (client/cell/part_files.h); and optionally records the part in
// a results store. The PLY is written as soon as the deviations are known,
// beside the plan's evaluation, which only reads them. Millimetres.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/remote/remote_client.h"
#include "core/cad/cad_settings.h"
#include "core/errormap/error_map.h"
#include "core/history/results_store.h"
#include "core/io/length_units.h"
#include "core/pipeline/inspection_report.h"

namespace surfinspect::client {

struct ErrorMapJob {
  std::string cloud, mesh;      // the files read
  std::string world_from_part;  // transform JSON; "" = identity
  std::string plan;             // plan JSON; "" = the surface against +-tolerance
  // One path per file of the catalogue; "" = not written. The PLY is required.
  std::string ply, csv, report, png, pdf, html, qif;
  std::string part_id;                 // the part in the reports; "" = the cloud's stem
  std::string cell_name = "errormap";  // the cell a record is filed under
  std::string frame = "part";          // coordinates of the PLY and the CSV: "part" | "world"
  int png_axis = -1;                   // merged clouds' view axis: 0 x, 1 y, 2 z, -1 thinnest
  ErrorMapSettings settings;
  // A STEP/IGES `mesh` is tessellated with these (core/cad/cad_import.h)
  // and cached in cad_cache.
  CadSettings cad;
  std::string cad_cache;
  // The units the cloud and the mesh files are in (core/io/length_units.h);
  // assumed millimetres are checked for plausibility. Transforms and the
  // plan are millimetres.
  InputUnit cloud_units, mesh_units;
};

struct ErrorMapJobResult {
  std::string part_id;
  InspectionReport report;  // as written to report.json
  // One line per failed characteristic and per defect, for people.
  std::vector<std::string> failed, defects;
  bool recorded = false;  // with a store: recorded now (false: it was already there)
};

// Progress lines for a log ("read 2056567 points and 4440 triangles in ...").
using JobLog = std::function<void(const std::string&)>;

// The whole command. `remote` computes on that server (null: in-process);
// `store` also records the part (null: no record). InvalidArgument for bad
// settings or a bad plan, before anything is computed; a file's own error
// otherwise. `warn` hears each unit doubt as soon as the files are read (the
// report carries them too). Runs on the calling thread's task arena.
absl::StatusOr<ErrorMapJobResult> RunErrorMapJob(const ErrorMapJob& job, RemoteClient* remote,
                                                 ResultsStore* store, const JobLog& log = {},
                                                 const JobLog& warn = {});

}  // namespace surfinspect::client

# Runs `surfinspect --help` and `surfinspect info` on files it makes itself
# with the CLI's siblings; fails on a non-zero exit or missing output.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${CLI} --help RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "info")
  message(FATAL_ERROR "--help failed: ${rc}\n${out}")
endif()
file(WRITE ${WORK}/tri.off "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
execute_process(COMMAND ${CLI} info ${WORK}/tri.off RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "triangles: 2" OR NOT out MATCHES "closed: no")
  message(FATAL_ERROR "info on a mesh failed: ${rc}\n${out}")
endif()
# holes: a mesh without any lists none; the demo part lists its five holes
# and its slot, and --plan prints them as plan entries.
execute_process(COMMAND ${CLI} holes ${WORK}/tri.off RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "^0 holes and slots")
  message(FATAL_ERROR "holes on a plain mesh failed: ${rc}\n${out}")
endif()
execute_process(COMMAND ${CLI} demo-cell --out ${WORK}/demo --parts 0 RESULT_VARIABLE rc
                OUTPUT_QUIET ERROR_QUIET)
execute_process(COMMAND ${CLI} holes ${WORK}/demo/part.stl RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "^6 holes and slots"
   OR NOT out MATCHES "\nslot +95.000 +-8.000")
  message(FATAL_ERROR "holes on the demo part failed: ${rc}\n${out}")
endif()
execute_process(COMMAND ${CLI} holes ${WORK}/demo/part.stl --plan --position-tolerance 0.25
                RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"name\": \"S1\"" OR NOT out MATCHES "\"name\": \"H5\""
   OR NOT out MATCHES "\"position_tolerance_mm\": 0.25")
  message(FATAL_ERROR "holes --plan failed: ${rc}\n${out}")
endif()
file(WRITE ${WORK}/c.pcd "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n1 2 3\nnan nan nan\n4 5 6\n7 8 9\n")
execute_process(COMMAND ${CLI} info ${WORK}/c.pcd RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "valid: 3" OR NOT out MATCHES "organized: yes \\(2 x 2\\)"
   OR NOT out MATCHES "viewpoint: translation 0 0 0, rotation \\(w x y z\\) 1 0 0 0 \\(not applied")
  message(FATAL_ERROR "info on a cloud failed: ${rc}\n${out}")
endif()
# A viewpoint that is reported, not applied: the bounds are the points' own.
file(WRITE ${WORK}/v.pcd "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 12.5 -3 0.25 0.5 -0.5 0.5 0.5\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n")
execute_process(COMMAND ${CLI} info ${WORK}/v.pcd RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0
   OR NOT out MATCHES "viewpoint: translation 12.5 -3 0.25, rotation \\(w x y z\\) 0.5 -0.5 0.5 0.5 \\(not applied to the points\\)"
   OR NOT out MATCHES "bounds min: 1.0000 2.0000 3.0000 mm\nbounds max: 4.0000 5.0000 6.0000 mm")
  message(FATAL_ERROR "info on a PCD with a viewpoint failed: ${rc}\n${out}")
endif()
# A Stanford-style range grid (obj_info num_cols/num_rows, range_grid) is organized.
file(WRITE ${WORK}/grid.ply "ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 3\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nelement range_grid 6\nproperty list uchar int vertex_indices\nend_header\n1 2 3\n4 5 6\n0\n1 1\n0\n0\n1 0\n0\n")
execute_process(COMMAND ${CLI} info ${WORK}/grid.ply RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "points: 6\nvalid: 2\norganized: yes \\(2 x 3\\)")
  message(FATAL_ERROR "info on a PLY range grid failed: ${rc}\n${out}")
endif()
# A real PCL stereo cloud (../shared/realdata beside the checkout, BSD), whose
# VIEWPOINT is a half turn about x: reported, and its points left as they are.
set(MUG ${CMAKE_CURRENT_LIST_DIR}/../../../shared/realdata/clouds/table_scene_mug_stereo_textured.pcd)
if(EXISTS ${MUG})
  execute_process(COMMAND ${CLI} info ${MUG} RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "organized: yes \\(640 x 480\\)"
     OR NOT out MATCHES "viewpoint: translation 0 0 0, rotation \\(w x y z\\) 0 1 0 0 \\(not applied to the points\\)"
     OR NOT out MATCHES "bounds min: -0.4564 -0.5107 0.6900 mm\nbounds max: 0.7152 0.1792 2.5927 mm")
    message(FATAL_ERROR "info on the real PCL cloud failed: ${rc}\n${out}")
  endif()
else()
  message(WARNING "SKIPPED the real-file check of info: no ${MUG}")
endif()
execute_process(COMMAND ${CLI} info ${WORK}/missing.pcd RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "cannot open")
  message(FATAL_ERROR "info on a missing file must fail clearly: ${rc}\n${err}")
endif()

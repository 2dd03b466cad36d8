# Runs `surfinspect errormap` on a plane, a 3 x 2 organized cloud (one NaN
# pixel, one point beyond --max-distance) and a world_from_part shift of
# 100 mm in x; checks the CSV row by row, the report, the PNG/PLY and the
# verdict switch, and that bad input fails clearly.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/plane.off "OFF\n4 2 0\n0 0 0\n10 0 0\n10 10 0\n0 10 0\n3 0 1 2\n3 0 2 3\n")
file(WRITE ${WORK}/c.pcd "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 6\nDATA ascii\n102 2 0.05\n105 5 -0.2\nnan nan nan\n108 8 0\n103 7 9\n104 4 0.5\n")
file(WRITE ${WORK}/t.json "{\"matrix\": [[1,0,0,100],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}")
set(ARGS errormap --cloud ${WORK}/c.pcd --mesh ${WORK}/plane.off --world-from-part ${WORK}/t.json
         --out ${WORK}/o.ply --csv ${WORK}/o.csv --report ${WORK}/o.json --png ${WORK}/o.png
         --tolerance 0.1 --threads 2)
execute_process(COMMAND ${CLI} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "matched 4" OR NOT out MATCHES "verdict: fail")
  message(FATAL_ERROR "errormap failed: ${rc}\n${out}\n${err}")
endif()
file(READ ${WORK}/o.csv csv)
set(want "x,y,z,deviation\n2,2,0.05,0.05\n5,5,-0.2,-0.2\nnan,nan,nan,nan\n8,8,0,0\n3,7,9,nan\n4,4,0.5,0.5\n")
if(NOT csv STREQUAL want)
  message(FATAL_ERROR "CSV differs (part frame, input order, nan where unmatched):\n${csv}")
endif()
file(READ ${WORK}/o.json report)
# Where the time went, per stage; the query holds its ordering, the total all.
foreach(stage read build query plan png write total)
  string(JSON t ERROR_VARIABLE terr GET "${report}" timing ${stage}_seconds)
  if(terr OR NOT t MATCHES "^[0-9.eE+-]+$")
    message(FATAL_ERROR "report timing lacks ${stage}_seconds: ${terr}")
  endif()
endforeach()
string(JSON order GET "${report}" timing order_seconds)
string(JSON query GET "${report}" timing query_seconds)
string(JSON total GET "${report}" timing total_seconds)
if(order GREATER query OR query GREATER total)
  message(FATAL_ERROR "timing does not nest: order ${order} query ${query} total ${total}")
endif()
if(NOT report MATCHES "\"verdict\": \"fail\"" OR NOT report MATCHES "\"matched\": 4"
   OR NOT report MATCHES "\"above\": 1" OR NOT report MATCHES "\"below\": 1")
  message(FATAL_ERROR "report lacks the verdict or counts:\n${report}")
endif()
file(READ ${WORK}/o.ply ply LIMIT 400)
if(NOT ply MATCHES "^ply\nformat binary_little_endian 1.0" OR NOT ply MATCHES "element vertex 5"
   OR NOT ply MATCHES "property float scalar_deviation\nproperty float quality\n")
  message(FATAL_ERROR "PLY header wrong:\n${ply}")
endif()
file(READ ${WORK}/o.png png LIMIT 4 HEX)
if(NOT png STREQUAL "89504e47")
  message(FATAL_ERROR "not a PNG: ${png}")
endif()
# Half the matched points are outside +-0.1: allowing 50% passes.
execute_process(COMMAND ${CLI} ${ARGS} --allowed-outside 0.5 RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "verdict: pass")
  message(FATAL_ERROR "--allowed-outside 0.5 should pass: ${rc}\n${out}")
endif()
execute_process(COMMAND ${CLI} errormap --cloud ${WORK}/c.pcd --mesh ${WORK}/missing.stl --out ${WORK}/x.ply
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "missing.stl")
  message(FATAL_ERROR "a missing mesh must fail clearly: ${rc}\n${err}")
endif()
execute_process(COMMAND ${CLI} ${ARGS} --tolerance -1 RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "a negative tolerance must be rejected")
endif()
if(EXISTS ${WORK}/x.ply)
  message(FATAL_ERROR "a failed run must not leave an output file")
endif()
# An inspection plan: a region over the whole plane with a wide band and a
# comparison point on the -0.2 mm point; the report holds their results.
file(WRITE ${WORK}/plan.json "{\"regions\": [{\"name\": \"all\", \"select\": {\"box_mm\": [[-1, -1, -1], [11, 11, 1]]}, \"tolerance_mm\": {\"lower\": -0.3, \"upper\": 0.6}}], \"points\": [{\"name\": \"P\", \"position_mm\": [5, 5, 0], \"radius_mm\": 1.0, \"tolerance_mm\": {\"lower\": -0.25, \"upper\": 0.1}}]}")
execute_process(COMMAND ${CLI} ${ARGS} --plan ${WORK}/plan.json RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "part: fail \\(3 characteristics, 0 defects\\)"
   OR NOT out MATCHES "failed surface: fail")
  message(FATAL_ERROR "errormap --plan failed: ${rc}\n${out}\n${err}")
endif()
file(READ ${WORK}/o.json report)
string(JSON schema GET "${report}" schema)
string(JSON verdict GET "${report}" verdict)
string(JSON n LENGTH "${report}" characteristics)
string(JSON rname GET "${report}" characteristics 1 name)
string(JSON region_verdict GET "${report}" characteristics 1 verdict)
string(JSON pname GET "${report}" characteristics 2 name)
string(JSON point_type GET "${report}" characteristics 2 type)
string(JSON point_verdict GET "${report}" characteristics 2 verdict)
string(JSON point_value GET "${report}" characteristics 2 value_mm)
string(JSON point_n GET "${report}" characteristics 2 points)
string(JSON defects LENGTH "${report}" defects)
string(JSON band GET "${report}" tolerance band_mm)
if(NOT schema STREQUAL "surfinspect.report/2" OR NOT verdict STREQUAL "fail" OR NOT n EQUAL 3
   OR NOT rname STREQUAL "all" OR NOT region_verdict STREQUAL "pass" OR NOT pname STREQUAL "P"
   OR NOT point_type STREQUAL "point" OR NOT point_verdict STREQUAL "pass" OR NOT point_n EQUAL 1
   OR NOT point_value MATCHES "^-0\\.2" OR NOT defects EQUAL 0 OR NOT band EQUAL 0.1)
  message(FATAL_ERROR "report/2 lacks the plan's characteristics:\n${report}")
endif()
# Bad plans are refused with the field named, before any output is written.
file(REMOVE ${WORK}/x.ply)
file(WRITE ${WORK}/bad1.json "{\"regions\": [{\"name\": \"r\", \"select\": {\"box_mm\": [[5, 0, 0], [1, 1, 1]]}}]}")
file(WRITE ${WORK}/bad2.json "{\"points\": [{\"name\": \"P\", \"position_mm\": [1, 1, 0], \"tolerance_mm\": {\"lower\": 0.2, \"upper\": 0.1}}]}")
file(WRITE ${WORK}/bad3.json "{\"tolerance\": 0.1}")
file(WRITE ${WORK}/bad4.json "{\"regions\": [{\"name\": \"r\", \"select\": {\"triangles\": [0, 2]}}]}")
foreach(bad "bad1.json|plan.regions\\[0\\].select.box_mm" "bad2.json|plan.points\\[0\\].tolerance_mm"
            "bad3.json|plan.tolerance: unknown key" "bad4.json|plan.regions\\[0\\].select.triangles\\[1\\]")
  string(REPLACE "|" ";" pair "${bad}")
  list(GET pair 0 file)
  list(GET pair 1 want)
  execute_process(COMMAND ${CLI} errormap --cloud ${WORK}/c.pcd --mesh ${WORK}/plane.off
                          --out ${WORK}/x.ply --plan ${WORK}/${file}
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "${want}" OR EXISTS ${WORK}/x.ply)
    message(FATAL_ERROR "${file} must be refused naming ${want}: ${rc}\n${err}")
  endif()
endforeach()
# --html: the self-contained report; a region name with markup and quotes is
# escaped, never markup.
file(WRITE ${WORK}/evil_plan.json "{\"regions\": [{\"name\": \"<script>x</script>'q'\", \"select\": {\"box_mm\": [[-1, -1, -1], [11, 11, 1]]}}]}")
execute_process(COMMAND ${CLI} ${ARGS} --plan ${WORK}/evil_plan.json --html ${WORK}/o.html
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 AND NOT rc EQUAL 1)
  message(FATAL_ERROR "errormap --html failed: ${rc}\n${out}\n${err}")
endif()
file(READ ${WORK}/o.html html)
string(FIND "${html}" "<script>x" raw)
string(FIND "${html}" "&lt;script&gt;x&lt;/script&gt;&#39;q&#39;" escaped)
if(NOT html MATCHES "^<!doctype html>" OR NOT raw EQUAL -1 OR escaped EQUAL -1)
  message(FATAL_ERROR "report.html is not the escaped page (raw at ${raw}, escaped at ${escaped})")
endif()

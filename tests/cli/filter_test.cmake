# Runs `surfinspect filter` as a user would, on an organized cloud it writes
# itself: a 30 x 20 plane at 0.25 mm pitch with 3 no-data pixels, one pulse
# (+10 mm) and a 2 x 2 patch lifted by 5 mm. With --min-cluster 10 exactly
# those 5 points must go; the report, the filtered cloud and the PNG are
# checked, and bad parameters must fail with a clear message.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

set(points "")
foreach(row RANGE 19)
  foreach(col RANGE 29)
    math(EXPR xi "${col} / 4")
    math(EXPR xf "${col} % 4 * 25 + 100")  # 100..175: the digits after "1"
    math(EXPR yi "${row} / 4")
    math(EXPR yf "${row} % 4 * 25 + 100")
    string(SUBSTRING ${xf} 1 2 xf)
    string(SUBSTRING ${yf} 1 2 yf)
    set(z 400)
    if(row EQUAL 5 AND col EQUAL 5)
      set(z 410)
    elseif(row GREATER_EQUAL 10 AND row LESS_EQUAL 11 AND col GREATER_EQUAL 20 AND col LESS_EQUAL 21)
      set(z 405)
    endif()
    if((row EQUAL 0 AND col EQUAL 0) OR (row EQUAL 19 AND col EQUAL 29) OR (row EQUAL 7 AND col EQUAL 7))
      string(APPEND points "nan nan nan\n")
    else()
      string(APPEND points "${xi}.${xf} ${yi}.${yf} ${z}\n")
    endif()
  endforeach()
endforeach()
file(WRITE ${WORK}/in.pcd "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 30\nHEIGHT 20\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 600\nDATA ascii\n${points}")

execute_process(COMMAND ${CLI} filter --in ${WORK}/in.pcd --out ${WORK}/out.pcd --min-cluster 10
                        --report ${WORK}/report.json --png ${WORK}/view.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "filter failed: ${rc}\n${out}\n${err}")
endif()

file(READ ${WORK}/report.json report)
foreach(pair "input_points=600" "valid_points=597" "kept=592" "removed=5" "clusters=3"
             "largest_cluster=592" "parameters;min_cluster_points=10"
             "parameters;connectivity=8" "parameters;link_distance_mm=0.5")
  string(REPLACE "=" ";" kv "${pair}")
  list(POP_BACK kv want)
  string(JSON got GET "${report}" ${kv})
  if(NOT got EQUAL want)
    message(FATAL_ERROR "report ${kv} = ${got}, want ${want}\n${report}")
  endif()
endforeach()
string(JSON seconds GET "${report}" seconds)
if(NOT seconds GREATER_EQUAL 0)
  message(FATAL_ERROR "report has no seconds\n${report}")
endif()

execute_process(COMMAND ${CLI} info ${WORK}/out.pcd RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "valid: 592" OR NOT out MATCHES "organized: yes \\(30 x 20\\)")
  message(FATAL_ERROR "filtered cloud is not the same grid with 592 points: ${rc}\n${out}")
endif()

file(READ ${WORK}/view.png magic LIMIT 8 HEX)
if(NOT magic STREQUAL "89504e470d0a1a0a")
  message(FATAL_ERROR "view.png is not a PNG: ${magic}")
endif()

# Bad parameters: a clear message and a non-zero exit, no output written.
foreach(bad "--link-distance;-1;link_distance_mm" "--link-distance;nan;link_distance_mm"
            "--connectivity;6;connectivity" "--min-fraction;2;min_fraction_of_largest")
  list(GET bad 0 flag)
  list(GET bad 1 value)
  list(GET bad 2 words)
  execute_process(COMMAND ${CLI} filter --in ${WORK}/in.pcd --out ${WORK}/bad.pcd ${flag} ${value}
                  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
  if(rc EQUAL 0 OR NOT err MATCHES "${words}" OR EXISTS ${WORK}/bad.pcd)
    message(FATAL_ERROR "${flag} ${value} must fail naming ${words}: ${rc}\n${err}")
  endif()
endforeach()

file(WRITE ${WORK}/flat.pcd "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n0 0 0\n1 0 0\n")
execute_process(COMMAND ${CLI} filter --in ${WORK}/flat.pcd --out ${WORK}/flat_out.pcd --png ${WORK}/flat.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "organized")
  message(FATAL_ERROR "--png on an unorganized cloud must fail clearly: ${rc}\n${err}")
endif()
execute_process(COMMAND ${CLI} filter --in ${WORK}/flat.pcd --out ${WORK}/flat_out.pcd --min-cluster 2
                        --report ${WORK}/flat.json
                RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ ${WORK}/flat.json report)
string(JSON removed GET "${report}" removed)
string(JSON organized GET "${report}" organized)
if(NOT rc EQUAL 0 OR NOT removed EQUAL 2 OR organized)
  message(FATAL_ERROR "unorganized filter: ${rc} removed=${removed} organized=${organized}\n${err}")
endif()

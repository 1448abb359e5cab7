# cvslam_run --mode dc is deterministic: two runs of the same scenario give identical
# trajectories and cooperation logs, cooperation actually fused landmarks, and the audit of
# the fused pairs against the truth (cross_uav_matches.json) finds them all right.
# Usage: cmake -DRUN=<cvslam_run> -DSCENARIO=<yaml> -DOUT=<dir> -P dc_determinism.cmake
file(REMOVE_RECURSE ${OUT})
foreach(i a b)
  execute_process(COMMAND ${RUN} --scenario ${SCENARIO} --mode dc --quiet --out ${OUT}/${i}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "cvslam_run --mode dc failed (${rc}): ${err}")
  endif()
endforeach()
foreach(f agent_1/trajectory.tum agent_2/trajectory.tum agent_1/coop.csv agent_2/coop.csv
          cross_uav_matches.json)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/a/${f} ${OUT}/b/${f}
                  RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "runs differ in ${f}")
  endif()
endforeach()
file(READ ${OUT}/a/agent_2/coop.csv log2)
file(READ ${OUT}/a/agent_1/coop.csv log1)
if(NOT "${log1}${log2}" MATCHES "\n[0-9.]+,fused,[0-9]+,[0-9]+,[1-9]")
  message(FATAL_ERROR "no landmark was fused in the run")
endif()
file(READ ${OUT}/a/agent_1/stats.json stats)
if(NOT stats MATCHES "bytes_sent_per_stream")
  message(FATAL_ERROR "stats.json lacks bytes_sent_per_stream")
endif()
# The audit of the fused pairs against the truth: with true ids every pair is one landmark.
file(READ ${OUT}/a/cross_uav_matches.json audit)
string(JSON fused GET "${audit}" fused)
string(JSON unknown GET "${audit}" fused_unknown)
string(JSON precision GET "${audit}" precision)
if(fused LESS 1 OR NOT unknown EQUAL 0 OR NOT precision EQUAL 1)
  message(FATAL_ERROR "cross_uav_matches.json: expected fused pairs, all right: ${audit}")
endif()
file(REMOVE_RECURSE ${OUT})

# Image-level cooperation needs the UAVs to map the same surface points. cvslam_run --mode dc
# --sensing images over the first 40 s (three crossings) of team3_aerial, with new landmarks
# offered by confirmation residual (the shipped frontend.new_landmark_order) and by detector
# response:
# the audit against the renderer's truth (cross_uav_matches.json) must find at least twice
# the twin pairs in view with the response order, and every fused pair right in both runs.
# Usage: cmake -DRUN=<cvslam_run> -DSOURCE=<source dir> -DOUT=<dir> -P new_landmark_order.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(READ ${SOURCE}/config/agent.yaml config)
string(REPLACE "new_landmark_order: confirmation" "new_landmark_order: response" config
       "${config}")
string(REGEX REPLACE "vocabulary: ([a-z_]+\\.cvoc)" "vocabulary: ${SOURCE}/config/\\1" config
       "${config}")
string(REGEX REPLACE "vocabulary_orb: ([a-z_]+\\.cvoc)" "vocabulary_orb: ${SOURCE}/config/\\1"
       config "${config}")
file(WRITE ${OUT}/response.yaml "${config}")
foreach(order response confirmation)
  set(cfg)
  if(order STREQUAL "response")
    set(cfg --config ${OUT}/response.yaml)
  endif()
  execute_process(COMMAND ${RUN} --scenario ${SOURCE}/config/scenarios/team3_aerial.yaml
                          --mode dc --sensing images --seed 41 --duration 40 --quiet ${cfg}
                          --out ${OUT}/${order}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "cvslam_run (${order}) failed (${rc}): ${err}")
  endif()
  file(READ ${OUT}/${order}/cross_uav_matches.json audit)
  string(JSON twins_${order} GET "${audit}" distinct_twin_pairs)
  string(JSON precision GET "${audit}" precision)
  message(STATUS "${order}: ${audit}")
  if(precision LESS 1.0)
    message(FATAL_ERROR "${order}: a fused cross-UAV pair is wrong: ${audit}")
  endif()
endforeach()
math(EXPR twice "2 * ${twins_confirmation}")
if(twins_response LESS twice OR twins_response LESS 4)
  message(FATAL_ERROR "twin pairs in view: response ${twins_response}, confirmation "
                      "${twins_confirmation}; expected at least twice as many (and ≥ 4)")
endif()
file(REMOVE_RECURSE ${OUT})

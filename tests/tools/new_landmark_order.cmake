# Image-level cooperation needs the UAVs to hold the same surface points. cvslam_run --mode dc
# --sensing images over the first 40 s (three crossings) of team3_aerial, seeds 41 and 42,
# audited against the renderer's truth (cross_uav_matches.json); every fused pair must be right
# in every run, and over the two seeds together:
#  - the thesis's exchange (in-state landmarks only: coop.map_shared_landmarks and
#    coop.offer_archived off) with new landmarks offered by confirmation residual (the shipped
#    frontend.new_landmark_order) and by detector response: the response order must find at
#    least twice the twin pairs in view;
#  - the shipped exchange (a peer's landmarks matched to unmapped observed points, archived
#    landmarks offered where a peer looks): at least three times the fused pairs of the
#    thesis's exchange, and at least 8, and a right pair fused on at least 5 of the 6 crossings.
# One seed alone is not enough for these counts: over seeds 41-46 a single run's crossings
# fused are 2 or 3 of 3 and its shipped pairs 5-17 (docs/cooperation.md).
# Usage: cmake -DRUN=<cvslam_run> -DSOURCE=<source dir> -DOUT=<dir> -P new_landmark_order.cmake
set(seeds 41 42)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
# The three exchanges as --set on the shipped configuration.
set(thesis_exchange --set coop.map_shared_landmarks=false --set coop.offer_archived=false)
set(sets_confirmation ${thesis_exchange})
set(sets_response ${thesis_exchange} --set frontend.new_landmark_order=response)
set(sets_shipped)
foreach(run confirmation response shipped)
  set(twins_${run} 0)
  set(fused_${run} 0)
endforeach()
set(crossings 0)
set(crossings_fused 0)
foreach(seed ${seeds})
  foreach(run confirmation response shipped)
    execute_process(COMMAND ${RUN} --scenario ${SOURCE}/config/scenarios/team3_aerial.yaml
                            --mode dc --sensing images --seed ${seed} --duration 40 --quiet
                            --config ${SOURCE}/config/agent.yaml ${sets_${run}}
                            --out ${OUT}/${run}_${seed}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "cvslam_run (${run}, seed ${seed}) failed (${rc}): ${err}")
    endif()
    file(READ ${OUT}/${run}_${seed}/cross_uav_matches.json audit)
    string(JSON twins GET "${audit}" distinct_twin_pairs)
    string(JSON fused GET "${audit}" fused)
    string(JSON precision GET "${audit}" precision)
    math(EXPR twins_${run} "${twins_${run}} + ${twins}")
    math(EXPR fused_${run} "${fused_${run}} + ${fused}")
    message(STATUS "${run}, seed ${seed}: ${audit}")
    if(precision LESS 1.0)
      message(FATAL_ERROR "${run}, seed ${seed}: a fused cross-UAV pair is wrong: ${audit}")
    endif()
    if(run STREQUAL "shipped")
      string(JSON n LENGTH "${audit}" crossings)
      string(JSON n_fused GET "${audit}" crossings_fused)
      math(EXPR crossings "${crossings} + ${n}")
      math(EXPR crossings_fused "${crossings_fused} + ${n_fused}")
    endif()
  endforeach()
endforeach()
math(EXPR min_crossings_fused "${crossings} - 1")
if(crossings LESS 6 OR crossings_fused LESS min_crossings_fused)
  message(FATAL_ERROR "shipped: ${crossings_fused} of ${crossings} crossings with a right pair "
                      "fused; expected all but one of at least 6")
endif()
math(EXPR twice "2 * ${twins_confirmation}")
if(twins_response LESS twice OR twins_response LESS 4)
  message(FATAL_ERROR "twin pairs in view: response ${twins_response}, confirmation "
                      "${twins_confirmation}; expected at least twice as many (and ≥ 4)")
endif()
math(EXPR thrice "3 * ${fused_confirmation}")
if(fused_shipped LESS thrice OR fused_shipped LESS 8)
  message(FATAL_ERROR "fused pairs: shipped ${fused_shipped}, thesis exchange "
                      "${fused_confirmation}; expected at least three times as many (and ≥ 8)")
endif()
file(REMOVE_RECURSE ${OUT})

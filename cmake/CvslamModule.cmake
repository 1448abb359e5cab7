# cvslam_module(<name> [DEPS <module>...] [LIBS <target>...])
#
# One library per module of common/: target `cvslam::<name>` (an alias of
# `cvslam_module_<name>`) from common/<name>/src/*.cpp,
# whose only include root is common/<name>/include (headers as "cvslam/<name>/...").
# DEPS are the cvslam modules it may use: their include roots reach this module only
# through these link lines, so including a header of a module that is not listed (directly
# or through a listed module) fails to compile. LIBS are third-party targets.
# A module with no sources is an INTERFACE library.
function(cvslam_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;LIBS" ${ARGN})
  set(dir ${CMAKE_CURRENT_SOURCE_DIR}/${name})
  file(GLOB sources CONFIGURE_DEPENDS ${dir}/src/*.cpp)
  set(target cvslam_module_${name})
  list(TRANSFORM ARG_DEPS PREPEND cvslam::)
  if(sources)
    add_library(${target} STATIC ${sources})
    target_include_directories(${target} PUBLIC ${dir}/include PRIVATE ${dir}/src)
    target_link_libraries(${target} PUBLIC ${ARG_DEPS} ${ARG_LIBS} PRIVATE cvslam_warnings)
    set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE ${dir}/include)
    target_link_libraries(${target} INTERFACE ${ARG_DEPS} ${ARG_LIBS})
  endif()
  add_library(cvslam::${name} ALIAS ${target})
  set_property(GLOBAL APPEND PROPERTY CVSLAM_MODULES ${target})
endfunction()

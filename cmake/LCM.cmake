# Locates Debian's LCM 1.3.1 (no CMake package, and `pkg-config lcm` fails without
# glib's -dev package; docs/architecture.md) and defines:
#   LCM::lcm          imported library target (headers + liblcm)
#   LCM_GEN_EXECUTABLE  the lcm-gen code generator
#   LCM_JAR             /usr/share/java/lcm.jar (for Java types and lcm-spy), if found
find_program(LCM_GEN_EXECUTABLE lcm-gen REQUIRED)
find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp REQUIRED)
find_library(LCM_LIBRARY lcm REQUIRED)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java NO_DEFAULT_PATH)

if(NOT TARGET LCM::lcm)
  add_library(LCM::lcm UNKNOWN IMPORTED)
  set_target_properties(LCM::lcm PROPERTIES
    IMPORTED_LOCATION "${LCM_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LCM_INCLUDE_DIR}")
endif()
message(STATUS "LCM: ${LCM_LIBRARY}, lcm-gen: ${LCM_GEN_EXECUTABLE}, jar: ${LCM_JAR}")

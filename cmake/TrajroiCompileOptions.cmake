# Compile options shared by every trajroi target.
#
# -ffp-contract=off: the fast ROI filter must decide exactly as the paper's double loop.
# Both evaluate the same inline expressions, but GCC may fuse a*b + c into an FMA in one
# inlined copy and not in the other, which changes the last bit. Forbidding contraction
# everywhere keeps every copy of an expression bit-identical.
function(trajroi_target_defaults target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
    -Wnon-virtual-dtor -Wold-style-cast -Wdouble-promotion
    -ffp-contract=off)
  # GCC 12 under -fsanitize=thread reports null dereferences inside libstdc++'s own string
  # moves (false positives); the check stays on in every other build.
  if(NOT CMAKE_CXX_FLAGS MATCHES "sanitize=thread")
    target_compile_options(${target} PRIVATE -Wnull-dereference)
  endif()
  if(TRAJROI_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# trajroi_library(<name> SOURCES ... ) — a library target `trajroi_<name>` with the alias
# `trajroi::<name>`, its `include/` folder public, and the defaults above.
function(trajroi_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES" ${ARGN})
  add_library(trajroi_${name} ${ARG_SOURCES})
  add_library(trajroi::${name} ALIAS trajroi_${name})
  target_include_directories(trajroi_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  trajroi_target_defaults(trajroi_${name})
endfunction()

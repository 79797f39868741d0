# vitri_target_options(<target>): warnings, sanitizers and floating-point flags for vitri's own targets.
# Nothing here leaks into CMAKE_CXX_FLAGS or into consumers (everything is PRIVATE), except the sanitizer
# flags of a VITRI_SANITIZE build (see below).
function(vitri_target_options target)
  target_compile_features(${target} PUBLIC cxx_std_17)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                             -Wno-sign-conversion -Wnon-virtual-dtor -Wold-style-cast
                                             -Woverloaded-virtual)
    # The exact predicates rely on every product and sum being rounded on its own (Dekker / Knuth
    # error-free transformations). A fused multiply-add would silently break them.
    target_compile_options(${target} PRIVATE -ffp-contract=off)
    if(VITRI_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  elseif(MSVC)
    target_compile_options(${target} PRIVATE /W4 /fp:precise)
  endif()
  if(VITRI_SANITIZE)
    # PUBLIC: a sanitized vitri is only usable by sanitized code. Eigen allocates differently under
    # AddressSanitizer (__SANITIZE_ADDRESS__ turns off its "malloc is already aligned" path), so an Eigen
    # matrix filled inside vitri and freed by a consumer compiled without it is a bad free (seen in
    # the install_consumer test).
    target_compile_options(${target} PUBLIC -fsanitize=${VITRI_SANITIZE})
    target_compile_options(${target} PRIVATE -fno-omit-frame-pointer -fno-sanitize-recover=all)
    target_link_options(${target} PUBLIC -fsanitize=${VITRI_SANITIZE})
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # GCC's flow analysis reports false "maybe-uninitialized" inside libstdc++ (std::function in
      # std::regex, used by Catch2) once ASan instruments the code; the sanitizers check this at run time.
      target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
    endif()
  endif()
endfunction()

# vitri_add_module(<name> SOURCES ... DEPENDS ...): one library per module, alias vitri::<name>.
function(vitri_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS" ${ARGN})
  if(ARG_SOURCES)
    set(scope PUBLIC)
    add_library(vitri_${name} ${ARG_SOURCES})
  else()  # header-only module
    set(scope INTERFACE)
    add_library(vitri_${name} INTERFACE)
  endif()
  add_library(vitri::${name} ALIAS vitri_${name})
  set_target_properties(vitri_${name} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(vitri_${name} ${scope}
                             $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                             $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(vitri_${name} ${scope} ${ARG_DEPENDS})
  if(ARG_SOURCES)
    vitri_target_options(vitri_${name})
  endif()
endfunction()

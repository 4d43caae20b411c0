# Used by run.sh as CMAKE_PROJECT_INCLUDE while the top-level CMakeLists.txt
# does not yet add_subdirectory(fuzz): it reads fuzz/CMakeLists.txt at the
# end of the top-level file, once the sdfc_compiler target exists (deferred
# code may include files but not add subdirectories).
if(NOT SDFC_FUZZ_ATTACHED)
  set(SDFC_FUZZ_ATTACHED ON)
  # Deferred arguments are expanded when the call runs, so keep the path now.
  set(SDFC_FUZZ_LISTS "${CMAKE_CURRENT_LIST_DIR}/CMakeLists.txt")
  cmake_language(DEFER CALL include "${SDFC_FUZZ_LISTS}")
endif()

# asval_state_core: the driver-free containers under the state tracker (sharded map, device-address map,
# memory-span overlap). Included by layer/state/CMakeLists.txt, or by tests/state when that file is absent.
# Paths are relative to this file, not to the including directory.
include_guard(GLOBAL)

find_package(Threads REQUIRED)

add_library(asval_state_core STATIC
  ${CMAKE_CURRENT_LIST_DIR}/concurrent_map.h
  ${CMAKE_CURRENT_LIST_DIR}/address_map.h
  ${CMAKE_CURRENT_LIST_DIR}/address_map.cpp
  ${CMAKE_CURRENT_LIST_DIR}/memory_range.h
  ${CMAKE_CURRENT_LIST_DIR}/memory_range.cpp)
# Headers can be included as "state/<name>.h" (tests) or "<name>.h" (the rest of layer/state).
target_include_directories(asval_state_core PUBLIC ${CMAKE_CURRENT_LIST_DIR}/.. ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(asval_state_core PUBLIC Vulkan::Headers Threads::Threads)
target_compile_features(asval_state_core PUBLIC cxx_std_17)
asval_warnings(asval_state_core)

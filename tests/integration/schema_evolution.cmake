# SPDX-License-Identifier: Apache-2.0
# Schema evolution of @appendable types over real Cyclone DDS (issue 16
# item 5): a test-only type in two versions (schema_evolution/evo_v1.idl,
# evo_v2.idl: one member appended to each struct), one peer program built
# per version, every writer/reader pairing across processes. Domain 185.
foreach(v 1 2)
  idlc_generate(TARGET evo_v${v}_gen FILES ${CMAKE_CURRENT_LIST_DIR}/schema_evolution/evo_v${v}.idl)
  add_executable(evo_peer_v${v} ${CMAKE_CURRENT_LIST_DIR}/schema_evolution/evo_peer.c ${CMAKE_CURRENT_BINARY_DIR}/evo_v${v}.c)
  add_dependencies(evo_peer_v${v} evo_v${v}_gen_generate)
  target_include_directories(evo_peer_v${v} PRIVATE ${CMAKE_CURRENT_BINARY_DIR})
  target_compile_definitions(evo_peer_v${v} PRIVATE EVO_VERSION=${v})
  target_link_libraries(evo_peer_v${v} PRIVATE CycloneDDS::ddsc)
endforeach()
viscera_integration_test(schema_evolution 185 schema_evolution_test.sh)

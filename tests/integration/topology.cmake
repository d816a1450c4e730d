# SPDX-License-Identifier: Apache-2.0
# Topology streaming end to end (issues 3 and 5): the adaptive kidney refines
# under a scripted probe; an early and a late-joining viewer both end on the
# server's final refined mesh; the recording holds one MeshState keyframe per
# topology version. Domain 80.
if(TARGET viscera-recorder)
  add_executable(rec_topology ${CMAKE_CURRENT_LIST_DIR}/rec_topology.c)
  target_link_libraries(rec_topology PRIVATE viscera_test_recording viscera_recording)
endif()
if(TARGET viscera-viewer)
  viscera_integration_test(topology_stream 80 topology_stream_test.sh)
endif()

# SPDX-License-Identifier: Apache-2.0
# Keyframe chunks (issue 14, key_chunks.c) in viscera_dds: the compact
# keyframe encoding deflates with zlib (Debian zlib1g-dev).
target_sources(viscera_dds PRIVATE ${CMAKE_CURRENT_LIST_DIR}/key_chunks.c)
find_package(ZLIB REQUIRED)
target_link_libraries(viscera_dds PRIVATE ZLIB::ZLIB)

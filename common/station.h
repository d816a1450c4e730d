/* SPDX-License-Identifier: Apache-2.0 */
/* station: the name of a station (a seat, an instructor's desk) that drives
 * tools (scene `station:`, idl ToolRole, a ToolCommand writer's USER_DATA).
 * A name is 1..STATION_NAME_MAX-1 characters of [A-Za-z0-9_.-]. No
 * networking here: the scene parser checks names with it, and so does the
 * DDS layer (dds/vdds.h) for what it announces and receives. */
#ifndef VISCERA_STATION_H
#define VISCERA_STATION_H

/* Bound of a station name, with the terminating NUL. */
#define STATION_NAME_MAX 32

/* Whether `name` (NULL: no) is a valid station name. */
int station_name_valid(const char *name);

#endif

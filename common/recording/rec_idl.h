/* SPDX-License-Identifier: Apache-2.0 */
/* rec_idl: the OMG IDL text of a recorded topic's type (rec_types.h), as
 * MCAP's "omgidl" schema encoding and Foxglove expect: every struct and
 * enum the type uses, each before its first use, inside its modules, with
 * @key members and the struct's extensibility (@final, @appendable,
 * @mutable). The text is rebuilt from the stored type information, so it
 * describes the samples as recorded, whatever this build's IDL says. */
#ifndef VISCERA_REC_IDL_H
#define VISCERA_REC_IDL_H

#include "recording/rec_types.h"

/* Appends the IDL of m->top and everything it uses to out. 0, or -1 with
 * err (out of memory, a type IDL cannot spell). */
int rt_idl_text(const rt_model_t *m, rt_str_t *out, verr_t *err);

#endif

/* resim_decode: one stored sample (recording.h: the 4-byte CDR encoding
 * header, then the payload) into a compiled-in IDL type.
 *
 * Kept minimal and local to viscera-resim (the same steps as the decoders
 * of tests/integration); a shared decoder in client/recorder can replace it
 * one call for one call. The payload is untrusted: Cyclone's normalizer
 * checks every length and bound against the type before anything is read. */
#ifndef VISCERA_RESIM_DECODE_H
#define VISCERA_RESIM_DECODE_H

#include <stdbool.h>
#include <stddef.h>

#include <dds/dds.h>

/* Decodes into *out (zeroed first). True on success; then the caller frees
 * the contents with resim_decode_free. On failure nothing is allocated. */
bool resim_decode(const void *cdr, size_t len, const dds_topic_descriptor_t *desc, void *out);
/* Frees what decoding allocated inside *sample (sequences), not the struct. */
void resim_decode_free(void *sample, const dds_topic_descriptor_t *desc);

#endif

/* SPDX-License-Identifier: MIT */
/*
 * bsf_frame_parsers.h - internal: the parser of each frame type, one file
 * each, that bsf_stream_decode.c's frame_types[] table dispatches to. A new
 * frame type adds its parser here and one entry to that table.
 */
#ifndef BSF_FRAME_PARSERS_H
#define BSF_FRAME_PARSERS_H

#include "bsf_stream_reader.h"

/* BSF_FRAME_TYPE_FEATURES (bsf_features_decode.c). */
bsf_status_t bsf_features_parse(reader_t *r, unsigned version, bsf_frame_t *out);

/* BSF_FRAME_TYPE_METADATA (bsf_metadata_decode.c). */
bsf_status_t bsf_metadata_parse(reader_t *r, unsigned version, bsf_frame_t *out);

/* BSF_FRAME_TYPE_MAP (bsf_map_frame.c): a map update, checked record by record. */
bsf_status_t bsf_map_parse(reader_t *r, unsigned version, bsf_frame_t *out);

#endif /* BSF_FRAME_PARSERS_H */

/* SPDX-License-Identifier: MIT */
/*
 * bsf_stream.h - the serial wire format (docs/FORMAT.md is the normative
 * spec): one frame per scan, COBS-framed with a 0x00 delimiter and checked
 * by CRC-32C, so a receiver that loses bytes resynchronises at the next 0x00.
 *
 * Encoder: a bsf_result_t plus a bsf_frame_info_t (sequence number,
 * timestamp, optional pose, quantisation step) become one frame, written to
 * a caller buffer or handed to a sink callback in chunks of at most 256
 * bytes. Decoder: bytes fed in arbitrary chunks come out as whole, fully
 * validated frames; damaged frames are dropped and counted.
 *
 * Every byte from the link is untrusted: the decoder checks every field
 * before a frame is delivered and never writes beyond its fixed buffers.
 *
 * Example usage: a scan's features as one frame in a buffer (link_write
 * stands for your UART or socket).
 *
 *     static uint8_t frame[BSF_FRAME_MAX_SIZE];
 *
 *     int send_scan(const bsf_result_t *result, uint32_t seq, uint64_t time_ms)
 *     {
 *         bsf_frame_info_t info;
 *         size_t len = 0;
 *         bsf_frame_info_init(&info);
 *         info.seq = seq;
 *         info.timestamp_ms = time_ms;
 *         if (bsf_frame_encode(&info, result, frame, sizeof frame, &len) != BSF_OK) {
 *             return -1;
 *         }
 *         return link_write(frame, len); // len bytes, the 0x00 delimiter last
 *     }
 *
 * Example usage: received bytes, in chunks of any size, back into frames
 * (call bsf_decoder_init(&decoder) once first; use_features stands for
 * your code).
 *
 *     static bsf_decoder_t decoder;
 *     static bsf_frame_t received;
 *
 *     void on_bytes(const uint8_t *data, size_t len)
 *     {
 *         while (len > 0u) {
 *             size_t used = 0;
 *             const int type = bsf_decoder_feed(&decoder, data, len, &used, &received);
 *             if (type < 0) {
 *                 return; // only for NULL arguments
 *             }
 *             if (type == (int)BSF_FRAME_TYPE_FEATURES) {
 *                 use_features(&received.result, received.has_pose ? &received.pose : NULL);
 *             }
 *             data += used;
 *             len -= used;
 *         }
 *     }
 *
 * CI compiles and runs both (test/contract/test_stream_header_examples.c).
 */
#ifndef BSF_STREAM_H
#define BSF_STREAM_H

#include "bsf_common.h"
#include "bsf_feature.h"

BSF_BEGIN_DECLS

/* ---- Format constants ---------------------------------------------------- */

/** Format version written by this encoder (upper nibble of payload byte 0).
 *  The decoder also reads version-1 feature frames (FORMAT.md section 5). */
#define BSF_FORMAT_VERSION 2u
/** Oldest format version the decoder still reads (features frames only). */
#define BSF_FORMAT_VERSION_MIN 1u
/** Frame type "features of one scan" (lower nibble of payload byte 0). */
#define BSF_FRAME_TYPE_FEATURES 1u
/** Frame type "stream metadata" (version 2): what produced the stream. */
#define BSF_FRAME_TYPE_METADATA 2u
/** Frame type "map update" (version 2): changes to the fused map (bsf_map.h). */
#define BSF_FRAME_TYPE_MAP 3u

/** Longest source name of a metadata frame, bytes of UTF-8 (no terminator). */
#define BSF_METADATA_SOURCE_MAX 64u
/** Largest |time origin| of a metadata frame, microseconds (2^62 - 1). */
#define BSF_METADATA_TIME_ORIGIN_MAX 4611686018427387903LL

/** Quantisation step of control points: unit on the wire is 0.1 mm. */
#define BSF_QUANT_STEP_UNIT 0.0001f
/** Smallest and largest quantisation step, metres (wire codes 1..10000). */
#define BSF_QUANT_STEP_MIN 0.0001f
#define BSF_QUANT_STEP_MAX 1.0f
/** Default quantisation step, metres (adds at most 2.5 mm per coordinate). */
#define BSF_QUANT_STEP_DEFAULT 0.005f
/** Largest |coordinate| / step a control point may have (2^23 - 1). */
#define BSF_QUANT_MAX_STEPS 8388607L
/** Largest |pose x|, |pose y| that can be sent, metres (int32 millimetres). */
#define BSF_POSE_XY_MAX 2000000.0f
/** Largest |pose theta| accepted, radians (wrapped into [-pi, pi) on the wire). */
#define BSF_POSE_THETA_MAX 25.0f
/** Largest E_curve that can be sent, metres (wire unit 0.5 mm). */
#define BSF_E_CURVE_MAX 1000.0f

/* ---- Worst-case sizes (depend only on the caps in bsf_config.h) ---------- */

/** COBS-encoded length of n bytes, worst case (delimiter not included). */
#define BSF_COBS_MAX_SIZE(n) ((n) + (n) / 254u + 1u)

/* The bounds below assume these caps (FORMAT.md section 7). */
#if BSF_MAX_POINTS > 65536 || BSF_MAX_SEGMENTS > 65536 || BSF_MAX_CTRL_PER_FEATURE > 64
#error "bsf_stream.h: the wire-format size bounds need smaller caps"
#endif

/** Largest features frame header (version/type byte, pose and extension
 * flags, seq, time stamp, pose, step, N, extraction time, feature count,
 * control point orders, beam count, geometry and cap-cut counters), bits. */
#define BSF_FRAME_HEADER_MAX_BITS 619u
/** Largest feature header (kind, point count, vertex mask, beams, E_curve), bits. */
#define BSF_FRAME_FEATURE_MAX_BITS 211u
/** Largest size of one distinct control point on the wire (two 26-bit codes), bits. */
#define BSF_FRAME_CTRL_MAX_BITS 52u
/** Size of the CRC-32C trailer, bytes. */
#define BSF_FRAME_CRC_SIZE 4u

/** Largest features payload + CRC (before COBS), bytes, for the caps. */
#define BSF_FEATURES_BODY_MAX_SIZE                                                                 \
    ((BSF_FRAME_HEADER_MAX_BITS + BSF_FRAME_FEATURE_MAX_BITS * (unsigned)BSF_MAX_SEGMENTS +        \
      BSF_FRAME_CTRL_MAX_BITS * (unsigned)BSF_MAX_CTRL_POINTS + 7u) /                              \
         8u +                                                                                      \
     BSF_FRAME_CRC_SIZE)

/** Largest metadata payload without its source name (version/type byte,
 * library version, method, target RMS, step, five caps, geometry, time
 * origin, name length), bits; each name byte adds 8. */
#define BSF_METADATA_FIXED_MAX_BITS 568u
/** Largest metadata payload + CRC (before COBS), bytes (independent of the caps). */
#define BSF_METADATA_BODY_MAX_SIZE                                                                 \
    ((BSF_METADATA_FIXED_MAX_BITS + 8u * BSF_METADATA_SOURCE_MAX + 7u) / 8u + BSF_FRAME_CRC_SIZE)
/** Largest encoded metadata frame on the wire, bytes. */
#define BSF_METADATA_MAX_SIZE (BSF_COBS_MAX_SIZE(BSF_METADATA_BODY_MAX_SIZE) + 1u)

/** Largest payload + CRC ("frame body", before COBS) of any frame type, bytes. */
#define BSF_FRAME_BODY_MAX_SIZE                                                                    \
    (BSF_FEATURES_BODY_MAX_SIZE > BSF_METADATA_BODY_MAX_SIZE ? BSF_FEATURES_BODY_MAX_SIZE          \
                                                             : BSF_METADATA_BODY_MAX_SIZE)

/** Largest encoded frame of any type on the wire (COBS body + 0x00 delimiter), bytes. */
#define BSF_FRAME_MAX_SIZE (BSF_COBS_MAX_SIZE(BSF_FRAME_BODY_MAX_SIZE) + 1u)

/* ---- Building blocks ----------------------------------------------------- */

/**
 * CRC-32C (Castagnoli): reflected polynomial 0x82F63B78, init 0xFFFFFFFF,
 * reflected in and out, xor-out 0xFFFFFFFF; check value of "123456789" is
 * 0xE3069283. Start with crc = 0 and pass each result back in to continue
 * over several pieces. data may be NULL only when len is 0.
 *
 * @return the CRC of everything processed so far.
 */
uint32_t bsf_crc32c(uint32_t crc, const uint8_t *data, size_t len);

/**
 * COBS-encode len bytes (no delimiter is appended).
 *
 * @param out      destination, cap bytes; must not overlap in.
 * @param out_len  receives the encoded length (at most BSF_COBS_MAX_SIZE(len)).
 * @return BSF_OK; BSF_ERR_ARG when in (with len > 0), out or out_len is NULL;
 *         BSF_ERR_BUFFER when cap is too small (*out_len is then the size needed).
 */
BSF_NODISCARD bsf_status_t bsf_cobs_encode(const uint8_t *in, size_t len, uint8_t *out, size_t cap,
                                           size_t *out_len);

/**
 * Decode one COBS block sequence (without its 0x00 delimiter).
 *
 * @return BSF_OK; BSF_ERR_ARG for NULL pointers; BSF_ERR_FORMAT when the
 *         input holds a 0x00 or ends inside a block; BSF_ERR_BUFFER when the
 *         decoded data exceed cap. Decoded length is at most len - 1.
 */
BSF_NODISCARD bsf_status_t bsf_cobs_decode(const uint8_t *in, size_t len, uint8_t *out, size_t cap,
                                           size_t *out_len);

/* ---- Encoder -------------------------------------------------------------- */

/** What a frame carries besides the features. */
typedef struct {
    uint32_t seq;          /**< sequence number (wraps), for loss detection */
    uint64_t timestamp_ms; /**< scan time, milliseconds since the stream's time origin
                                (bsf_metadata_t.time_origin_us) */
    uint8_t has_pose;      /**< 1: pose is sent (laser pose in the world frame) */
    /** |x|, |y| <= BSF_POSE_XY_MAX metres, sent in 1 mm units; |theta| <=
     * BSF_POSE_THETA_MAX radians, sent in 2*pi/65536 units */
    bsf_pose_t pose;
    float quant_step;      /**< control point step, metres, [BSF_QUANT_STEP_MIN, _MAX],
                                rounded to 0.1 mm */
    uint8_t has_geometry;  /**< 1: this scan's geometry travels in the frame (with
                                result->stats.n_beams, which must then be >= 1): for a
                                scan whose geometry differs from the stream's metadata */
    float angle_min;       /**< radians, finite: angle of beam 0 (with has_geometry) */
    float angle_increment; /**< radians, finite: between beams (with has_geometry) */
} bsf_frame_info_t;

/** Fill info with zeros, no pose, no geometry and quant_step = BSF_QUANT_STEP_DEFAULT. */
void bsf_frame_info_init(bsf_frame_info_t *info);

/**
 * Encode one scan's result into a complete frame: COBS(payload || CRC) || 0x00.
 * Only the first result->n_features features are read; each one's control
 * points are result->ctrl[ctrl_first .. ctrl_first + n_ctrl - 1]. A vertex
 * (two consecutive flagged slots whose values quantise alike) travels once.
 * The cap-cut stats travel when stats.cut is not 0, stats.n_beams when a
 * feature wraps (first_beam > last_beam: beams first_beam .. n_beams - 1,
 * then 0 .. last_beam) or when info->has_geometry is set.
 *
 * @param buf      destination, or NULL to only compute the size.
 * @param cap      size of buf in bytes (ignored when buf is NULL).
 * @param out_len  receives the exact frame size in bytes (also when buf is
 *                 NULL, and on BSF_ERR_BUFFER: the size needed).
 * @return BSF_OK; BSF_ERR_ARG when info, result or out_len is NULL, or a value
 *         cannot be represented: non-finite or out-of-range control point
 *         (|coordinate| / step > BSF_QUANT_MAX_STEPS), pose, quant_step,
 *         E_curve or geometry angles; has_geometry > 1, or 1 with
 *         stats.n_beams 0; n_ctrl < 3 or > BSF_MAX_CTRL_PER_FEATURE; control points
 *         outside result->n_ctrl; a flagged vertex slot without an equal
 *         partner; beams >= BSF_MAX_POINTS, or >= stats.n_beams when that is
 *         not 0; a wrapping feature (first_beam > last_beam) when
 *         stats.n_beams is 0; n_points above the beams of the run; kind > 1;
 *         stats.n_valid > BSF_MAX_POINTS, above a non-zero stats.n_beams or
 *         smaller than the points in features; stats.cut with bits other
 *         than BSF_CUT_*, cut counters that are not 0 while cut is 0, or
 *         n_cut_keypoints / n_cut_segments above BSF_MAX_POINTS or
 *         n_cut_points above the valid points outside the features;
 *         BSF_ERR_CAPACITY when n_features > BSF_MAX_SEGMENTS or n_ctrl >
 *         BSF_MAX_CTRL_POINTS; BSF_ERR_BUFFER when buf is not NULL and cap is
 *         smaller than the frame (nothing is claimed written). The input is
 *         fully validated before the first byte is written.
 */
BSF_NODISCARD bsf_status_t bsf_frame_encode(const bsf_frame_info_t *info,
                                            const bsf_result_t *result, uint8_t *buf, size_t cap,
                                            size_t *out_len);

/**
 * Receives encoded bytes from bsf_frame_encode_sink(), in order.
 * @return 0 when the bytes were taken, non-zero to abort the frame.
 */
typedef int (*bsf_sink_fn)(void *ctx, const uint8_t *data, size_t len);

/** Working memory of bsf_frame_encode_sink(): one COBS block (no state kept between calls). */
typedef struct {
    uint8_t block[256];
} bsf_encoder_t;

/**
 * Encode like bsf_frame_encode() but hand the bytes to sink, one COBS block
 * (at most 256 bytes, the last one ending with the 0x00 delimiter) per call,
 * so a UART or DMA queue can drain them as they come.
 *
 * @param work     caller-owned working memory.
 * @param written  optional (may be NULL): receives the bytes given to sink.
 * @return BSF_OK; the same BSF_ERR_ARG / BSF_ERR_CAPACITY as
 *         bsf_frame_encode() (then sink is never called); BSF_ERR_ARG for a
 *         NULL work or sink; BSF_ERR_BUFFER when sink returned non-zero: the
 *         frame was cut short and a receiver drops it (send a 0x00 before the
 *         next frame so that it does not swallow it).
 */
BSF_NODISCARD bsf_status_t bsf_frame_encode_sink(bsf_encoder_t *work, const bsf_frame_info_t *info,
                                                 const bsf_result_t *result, bsf_sink_fn sink,
                                                 void *ctx, size_t *written);

/* ---- Metadata frame ------------------------------------------------------- */

/**
 * What produced a stream (frame type BSF_FRAME_TYPE_METADATA, FORMAT.md
 * section 3.6): a sender writes one at the start of a stream, again whenever
 * a field changes, and at least every few frames so that a receiver joining
 * a live link learns it soon. Floats travel as their exact IEEE-754 binary32
 * bit patterns. Start from bsf_metadata_init().
 */
typedef struct {
    uint16_t lib_version_major; /**< library that encoded the stream */
    uint16_t lib_version_minor;
    uint16_t lib_version_patch;
    uint8_t method;         /**< bsf_method_t of the extraction (0..255; unknown values are kept) */
    float target_rms;       /**< PDM refinement target, metres, finite and >= 0 (0: not used) */
    float quant_step;       /**< control point step, metres, as in bsf_frame_info_t */
    uint32_t max_points;    /**< sender's caps that bound its frames (BSF_MAX_POINTS ...), */
    uint32_t max_keypoints; /**< each 1..65535 */
    uint32_t max_segments;  /**< */
    uint32_t max_ctrl_per_feature; /**< */
    uint32_t max_ctrl_points;      /**< */
    uint32_t n_beams;              /**< beams per scan, 0..65535; 0: geometry unknown */
    float angle_min;               /**< radians, angle of beam 0, finite */
    float angle_increment;         /**< radians between beams (may be negative), finite */
    float range_min;               /**< metres, finite, >= 0 */
    float range_max;               /**< metres, finite, >= range_min */
    uint8_t has_time_origin;       /**< 1: time_origin_us is known */
    int64_t time_origin_us;        /**< Unix time, microseconds, of frame timestamp 0;
                                        |value| <= BSF_METADATA_TIME_ORIGIN_MAX */
    uint8_t source_len;            /**< bytes in source, 0..BSF_METADATA_SOURCE_MAX (0: none) */
    char source[BSF_METADATA_SOURCE_MAX + 1u]; /**< source name, well-formed UTF-8 without
                                                    control characters; NUL-terminated when
                                                    decoded (the encoder reads source_len bytes) */
} bsf_metadata_t;

/** Fill m with this library's version, this build's caps, the default step,
 *  method 0, target_rms 0, unknown geometry, no time origin and no source. */
void bsf_metadata_init(bsf_metadata_t *m);

/**
 * Encode a metadata frame, like bsf_frame_encode() (buf may be NULL to get
 * the size; at most BSF_METADATA_MAX_SIZE bytes).
 *
 * @return BSF_OK; BSF_ERR_ARG when m or out_len is NULL or a field is out
 *         of its documented range (a non-finite float, range_min < 0 or
 *         > range_max, a cap of 0 or above 65535, n_beams above 65535, a
 *         step outside [BSF_QUANT_STEP_MIN, _MAX], a time origin too large,
 *         source_len above BSF_METADATA_SOURCE_MAX, a source that is not
 *         well-formed UTF-8 or holds a control character); BSF_ERR_BUFFER
 *         when buf is not NULL and cap is too small.
 */
BSF_NODISCARD bsf_status_t bsf_metadata_encode(const bsf_metadata_t *m, uint8_t *buf, size_t cap,
                                               size_t *out_len);

/** Encode a metadata frame to a sink, like bsf_frame_encode_sink(). */
BSF_NODISCARD bsf_status_t bsf_metadata_encode_sink(bsf_encoder_t *work, const bsf_metadata_t *m,
                                                    bsf_sink_fn sink, void *ctx, size_t *written);

/* ---- Decoder -------------------------------------------------------------- */

/**
 * One decoded frame: features (type BSF_FRAME_TYPE_FEATURES) or metadata
 * (BSF_FRAME_TYPE_METADATA).
 *
 * Features: `result` holds the features as the encoder saw them: control
 * points dequantised (within half a step of the originals), vertices
 * expanded to two flagged copies, ctrl_first the running sum of n_ctrl,
 * E_curve in 0.5 mm steps; result.stats carries n_valid, n_in_features,
 * n_ctrl, n_features, time_ns (= time_us * 1000), the cap-cut fields (cut,
 * n_cut_keypoints, n_cut_segments, n_cut_points) and n_beams when known (the
 * frame carries it when a feature wraps through the seam of a full-circle
 * scan or with its own geometry; otherwise bsf_decoder_feed() takes it from the last metadata frame
 * it delivered, and bsf_frame_decode() leaves 0). The other stats are 0 (they do not travel).
 * `metadata` is not touched.
 *
 * Metadata: `metadata` is filled; seq, timestamp_ms, pose, time_us and the
 * geometry are 0,
 * quant_step is metadata.quant_step, and result holds no features (counts
 * and stats 0; its arrays are not touched).
 *
 * Map update (BSF_FRAME_TYPE_MAP, bsf_map.h): the payload has been checked
 * for well-formedness; seq is the map frame's sequence number, the other
 * fields are 0 as for metadata; apply payload with bsf_map_rx_apply().
 */
typedef struct {
    uint8_t version;       /**< format version of the frame (1 or 2) */
    uint8_t type;          /**< BSF_FRAME_TYPE_FEATURES or BSF_FRAME_TYPE_METADATA */
    uint32_t seq;          /**< sequence number */
    uint64_t timestamp_ms; /**< milliseconds since the stream's time origin (metadata) */
    uint8_t has_pose;      /**< 1 when pose is valid */
    /** x, y in metres (1 mm resolution); theta in radians in [-pi, pi)
     * (2*pi/65536 resolution) */
    bsf_pose_t pose;
    float quant_step;        /**< metres */
    uint32_t time_us;        /**< extraction time, microseconds (<= 4 294 967) */
    uint8_t has_geometry;    /**< 1: the frame carries its scan's geometry (below, and
                                  result.stats.n_beams); 0: the metadata's applies */
    float angle_min;         /**< radians (with has_geometry) */
    float angle_increment;   /**< radians (with has_geometry) */
    bsf_result_t result;     /**< features, control points, vertex flags, stats */
    bsf_metadata_t metadata; /**< only for type BSF_FRAME_TYPE_METADATA */
    const uint8_t *payload;  /**< the frame's checked payload (CRC excluded), inside the
                                  decoder's buffer (bsf_decoder_feed: valid until the next
                                  call) or the caller's body (bsf_frame_decode); for a map
                                  frame (BSF_FRAME_TYPE_MAP) hand it to bsf_map_rx_apply() */
    size_t payload_len;      /**< bytes at payload */
} bsf_frame_t;

/**
 * Decode one frame body (payload || CRC, i.e. the COBS-decoded bytes between
 * two delimiters) into out. out is written only when the whole frame is valid.
 *
 * @return BSF_OK; BSF_ERR_ARG for NULL pointers; BSF_ERR_CRC when the CRC
 *         does not match (or len < 5); BSF_ERR_VERSION for a version other
 *         than 1 or 2, or a type this decoder does not know (version 1: type
 *         1 only; version 2: types 1, 2 and 3); BSF_ERR_FORMAT for
 *         any malformed or out-of-range field (including an extraction time
 *         above 4 294 967 us, which bsf_stats_t.time_ns cannot hold), a
 *         truncated code, non-zero padding or a trailing byte;
 *         BSF_ERR_CAPACITY when the frame exceeds this build's caps.
 */
BSF_NODISCARD bsf_status_t bsf_frame_decode(const uint8_t *body, size_t len, bsf_frame_t *out);

/** Decoder counters; they only grow (wrapping at 2^32) until bsf_decoder_init(). */
typedef struct {
    uint32_t frames_ok;           /**< frames delivered */
    uint32_t bad_crc;             /**< dropped: CRC mismatch or shorter than 5 bytes */
    uint32_t malformed;           /**< dropped: COBS error, malformed field, over the caps */
    uint32_t unsupported_version; /**< dropped: version this decoder does not know */
    uint32_t unknown_type;        /**< skipped: known version, unknown frame type */
    uint32_t metadata;            /**< metadata frames delivered (included in frames_ok) */
    uint32_t oversize;            /**< dropped: longer than BSF_FRAME_BODY_MAX_SIZE */
    uint32_t bytes_skipped;       /**< bytes of all dropped frames (delimiters excluded) */
} bsf_decoder_stats_t;

/** Stream decoder state: the body of the frame being received and counters. */
typedef struct {
    uint8_t body[BSF_FRAME_BODY_MAX_SIZE]; /**< COBS-decoded bytes of the current frame */
    size_t len;                            /**< bytes in body */
    size_t raw_len;                        /**< wire bytes of the current frame so far */
    uint32_t crc;                          /**< running CRC-32C over body */
    uint8_t block_left;                    /**< data bytes left in the current COBS block */
    uint8_t block_code;                    /**< code of the current block (0: none yet) */
    uint8_t overflow;                      /**< 1: current frame too long, skipping it */
    uint32_t meta_n_beams; /**< beam count of the last metadata frame delivered (0: none) */
    bsf_decoder_stats_t stats;
} bsf_decoder_t;

/** Reset dec to "between frames" with zero counters and no metadata seen.
 *  dec must not be NULL. */
void bsf_decoder_init(bsf_decoder_t *dec);

/**
 * Feed received bytes. Consumes bytes until a valid frame is complete (it is
 * then written to *out and 1 is returned) or data is exhausted (0). Call it
 * again with data + *consumed to continue. Work is O(1) per byte, plus one
 * parse of the frame (O(frame size)) at its delimiter. The stream start
 * counts as a frame boundary; a 0x00 always ends a frame, so after garbage
 * or lost bytes the decoder is back in step at the next delimiter. Empty
 * frames (0x00 0x00) are ignored. *out is written only for a delivered frame.
 * A features frame that does not carry its beam count gets, in
 * result.stats.n_beams, the n_beams of the last metadata frame delivered
 * (when its features and N fit in that many beams).
 *
 * @param consumed receives the number of bytes of data used (<= len).
 * @return the type of the frame delivered into *out: BSF_FRAME_TYPE_FEATURES
 *         (1), BSF_FRAME_TYPE_METADATA (2) or BSF_FRAME_TYPE_MAP (3, bsf_map.h),
 *         equal to out->type; 0 when all
 *         of data was consumed without completing a frame; BSF_ERR_ARG for
 *         NULL pointers (data may be NULL when len is 0).
 */
BSF_NODISCARD int bsf_decoder_feed(bsf_decoder_t *dec, const uint8_t *data, size_t len,
                                   size_t *consumed, bsf_frame_t *out);

BSF_END_DECLS

#endif /* BSF_STREAM_H */

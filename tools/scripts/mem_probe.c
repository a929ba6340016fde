/* SPDX-License-Identifier: MIT */
/*
 * mem_probe.c - compiled (never linked or run) by tools/mem_report.py: each
 * array below is exactly as large as one of bsf's caller-owned objects, so
 * the object file's symbol sizes (nm -S) are their sizeof for the compiler
 * and caps it was built with, cross compilers included.
 */
#include "bsf/bsf.h"

unsigned char bsf_sizeof_extractor_t[sizeof(bsf_extractor_t)];
unsigned char bsf_sizeof_result_t[sizeof(bsf_result_t)];
unsigned char bsf_sizeof_points_t[sizeof(bsf_points_t)];
unsigned char bsf_sizeof_falko_work_t[sizeof(bsf_falko_work_t)];
unsigned char bsf_sizeof_bid_work_t[sizeof(bsf_bid_work_t)];
unsigned char bsf_sizeof_pdm_work_t[sizeof(bsf_pdm_work_t)];
unsigned char bsf_sizeof_encoder_t[sizeof(bsf_encoder_t)];
unsigned char bsf_sizeof_decoder_t[sizeof(bsf_decoder_t)];

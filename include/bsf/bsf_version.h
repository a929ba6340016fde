/* SPDX-License-Identifier: MIT */
/*
 * bsf_version.h - version of the bsf library (semantic versioning).
 *
 * The BSF_VERSION_* macros are the version of the headers a program was
 * compiled with; bsf_version() is the version of the library it runs with.
 * The build checks that these numbers equal project(VERSION) in
 * CMakeLists.txt, so the two cannot drift apart.
 */
#ifndef BSF_VERSION_H
#define BSF_VERSION_H

#include "bsf_abi.h"

#define BSF_VERSION_MAJOR 0
#define BSF_VERSION_MINOR 2
#define BSF_VERSION_PATCH 0
/** "MAJOR.MINOR.PATCH" of these headers. */
#define BSF_VERSION_STRING "0.2.0"
/** The version as one comparable number: MAJOR * 10000 + MINOR * 100 + PATCH. */
#define BSF_VERSION_NUMBER (BSF_VERSION_MAJOR * 10000 + BSF_VERSION_MINOR * 100 + BSF_VERSION_PATCH)

BSF_BEGIN_DECLS

/** Version of the linked library, "MAJOR.MINOR.PATCH"; never NULL. */
const char *bsf_version(void);

BSF_END_DECLS

#endif /* BSF_VERSION_H */

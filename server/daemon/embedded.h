/*
 * embedded.h — files served verbatim by spinmodald, embedded at build time.
 *
 * server/daemon/embed.py turns files of the source tree (the JSON files of schemas/, the `/`
 * page, later the web front end) into a generated embedded.c with one
 * table entry per URL path.  Only these paths are ever served from "files":
 * nothing is read from disk at run time, so no request path can reach
 * outside them.
 */
#ifndef SPINMODAL_EMBEDDED_H
#define SPINMODAL_EMBEDDED_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct embedded_file {
    const char *path;          /* URL path, e.g. "/openapi.json" */
    const char *content_type;  /* e.g. "application/json" */
    const unsigned char *data; /* file bytes (also NUL-terminated) */
    size_t len;                /* bytes, without the NUL */
} embedded_file;

/** The file served at URL path (exact match), or NULL. */
const embedded_file *embedded_find(const char *path);

/** Number of files, and file i (0 <= i < count), for listings and tests. */
size_t embedded_count(void);
const embedded_file *embedded_at(size_t i);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_EMBEDDED_H */

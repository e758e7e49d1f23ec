/*
 * main.c — replay driver: runs a fuzz target without a fuzzing engine.
 *
 * Usage: fuzz_codec_replay [-libfuzzer-flags ignored] FILE|DIR...
 *
 * How it fits: the fuzz targets only define LLVMFuzzerTestOneInput (fuzz.h).
 * Linked with -fsanitize=fuzzer they become libFuzzer binaries; linked with
 * this file they build with any compiler (gcc, sanitizers or not) and replay
 * the corpus and any crash file as a plain regression test, as dav1d does.
 * Every FILE is fed once; a DIR is walked recursively in sorted name order
 * (dot files skipped).  Each input is named on stdout before it runs, so a
 * crash (abort() in the target, a sanitizer report) points at its file.
 * Exit status 0 when every input ran; 1 when a file could not be read or no
 * input was found; 2 on a usage error.
 */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz.h"

#define REPLAY_MAX_INPUT ((size_t)64 * 1024 * 1024) /* bytes read from one file */

/* Counters of one replay run. */
typedef struct replay {
    long inputs;  /* inputs fed to the target */
    long errors;  /* files or directories that could not be read */
} replay;

static void replay_path(replay *rp, const char *path);

/*
 * Whole file into a malloc'd buffer of exactly its size (1 byte for an empty
 * file), so ASan sees any read past the end; NULL on error.
 */
static uint8_t *replay_read(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    uint8_t *buf = NULL, *grown;
    size_t cap = 0, n = 0, got;

    if (!f)
        return NULL;
    do {
        if (n == cap) {
            cap = cap ? 2 * cap : 65536;
            if (cap > REPLAY_MAX_INPUT + 1 || !(grown = realloc(buf, cap)))
                goto fail;
            buf = grown;
        }
        got = fread(buf + n, 1, cap - n, f);
        n += got;
    } while (got > 0);
    if (ferror(f) || n > REPLAY_MAX_INPUT)
        goto fail;
    fclose(f);
    if ((grown = realloc(buf, n ? n : 1)) != NULL)
        buf = grown;
    *len = n;
    return buf;
fail:
    free(buf);
    fclose(f);
    return NULL;
}

/* Feed one file to the target. */
static void replay_file(replay *rp, const char *path)
{
    size_t len = 0;
    uint8_t *data = replay_read(path, &len);

    if (!data) {
        fprintf(stderr, "replay: cannot read %s\n", path);
        rp->errors++;
        return;
    }
    printf("replay: %s (%zu bytes)\n", path, len);
    fflush(stdout);
    LLVMFuzzerTestOneInput(data, len);
    rp->inputs++;
    free(data);
}

static int replay_cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Names in dir (no dot files), sorted; NULL on error.  *n receives the count. */
static char **replay_list(const char *dir, size_t *n)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char **names = NULL, **grown;
    size_t cap = 0, k = 0;

    if (!d)
        return NULL;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        if (k == cap) {
            cap = cap ? 2 * cap : 64;
            if (!(grown = realloc(names, cap * sizeof(*names))))
                goto fail;
            names = grown;
        }
        if (!(names[k] = strdup(e->d_name)))
            goto fail;
        k++;
    }
    closedir(d);
    if (k)
        qsort(names, k, sizeof(*names), replay_cmp);
    *n = k;
    return names ? names : calloc(1, sizeof(*names));
fail:
    while (k > 0)
        free(names[--k]);
    free(names);
    closedir(d);
    return NULL;
}

/* Every entry of a directory, recursively. */
static void replay_dir(replay *rp, const char *dir)
{
    size_t i, n = 0;
    char **names = replay_list(dir, &n);

    if (!names) {
        fprintf(stderr, "replay: cannot list %s\n", dir);
        rp->errors++;
        return;
    }
    for (i = 0; i < n; i++) {
        size_t len = strlen(dir) + 1 + strlen(names[i]) + 1;
        char *path = malloc(len);
        if (path) {
            snprintf(path, len, "%s/%s", dir, names[i]);
            replay_path(rp, path);
        } else {
            rp->errors++;
        }
        free(path);
        free(names[i]);
    }
    free(names);
}

static void replay_path(replay *rp, const char *path)
{
    struct stat sb;

    if (stat(path, &sb) != 0) {
        fprintf(stderr, "replay: cannot stat %s\n", path);
        rp->errors++;
    } else if (S_ISDIR(sb.st_mode)) {
        replay_dir(rp, path);
    } else {
        replay_file(rp, path);
    }
}

int main(int argc, char **argv)
{
    replay rp = {0, 0};
    int i, paths = 0;

    for (i = 1; i < argc; i++) {
        if (argv[i][0] == '-' && argv[i][1] != '\0')
            continue; /* a libFuzzer flag: the same command line works for both */
        replay_path(&rp, argv[i]);
        paths++;
    }
    if (paths == 0) {
        fprintf(stderr, "usage: %s FILE|DIR...\n", argv[0]);
        return 2;
    }
    printf("replay: %ld inputs, %ld unreadable\n", rp.inputs, rp.errors);
    return rp.errors > 0 || rp.inputs == 0 ? 1 : 0;
}

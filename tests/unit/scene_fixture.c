/* scene_fixture.c - see scene_fixture.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "scene_fixture.h"

char *fixture_write_temp(const char *text)
{
    char *path = strdup("/tmp/bspvga_test_XXXXXX");
    assert_non_null(path);
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    size_t n = strlen(text);
    assert_int_equal(write(fd, text, n), (ssize_t)n);
    close(fd);
    return path;
}

int fixture_compile_text(const char *text, const bspc_options *opt, uint8_t **blob, size_t *len, bspc_stats *st,
                         char *err, size_t errlen)
{
    char *path = fixture_write_temp(text);
    int rc = bspc_compile(path, opt, blob, len, st, err, errlen);
    unlink(path);
    free(path);
    if (rc) fprintf(stderr, "%s\n", err);
    return rc;
}

uint32_t fixture_load_text(const char *text, uint8_t **blob, scene *s)
{
    char err[512];
    size_t len = 0;
    assert_int_equal(fixture_compile_text(text, NULL, blob, &len, NULL, err, sizeof err), 0);
    assert_int_equal(scene_load(s, *blob, (uint32_t)len, NULL), SCENE_OK);
    return (uint32_t)len;
}

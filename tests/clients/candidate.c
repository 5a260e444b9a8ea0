/* A wirecheck candidate in C: the candidate protocol, version 1 (docs/protocol.md).
 *
 * Projects with the request's OpenCV matrices: p_cv = R X + t; a point is
 * clipped (NaN, NaN) when its depth z_cv is outside [near, far]; otherwise
 *   perspective:   u = K00 x/z + K02,  v = K11 y/z + K12
 *   orthographic:  u = K00 x   + K02,  v = K11 y   + K12   (K is affine there)
 *
 * Build: cc -O2 -o candidate candidate.c -lm
 * Run:   crosscheck --candidate-cmd ./candidate
 *
 * The wire is little-endian float64; this file assumes a little-endian host.
 * The JSON line is read with a tiny scanner for the few keys it needs.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HEADER "wirecheck-candidate 1\n"
#define MAX_LINE 65536

/* The `count` numbers after "key": (nested brackets and commas skipped). */
static int numbers(const char *line, const char *key, double *out, int count) {
    char pattern[64];
    snprintf(pattern, sizeof pattern, "\"%s\":", key);
    const char *s = strstr(line, pattern);
    if (!s) return 0;
    s += strlen(pattern);
    for (int i = 0; i < count; i++) {
        while (*s == '[' || *s == ']' || *s == ',' || *s == ' ') s++;
        char *end;
        out[i] = strtod(s, &end);
        if (end == s) return 0;
        s = end;
    }
    return 1;
}

static void fail(const char *message) {
    printf("{\"error\": \"%s\"}\n", message);
    fflush(stdout);
}

int main(void) {
    static char line[MAX_LINE];
    if (!fgets(line, sizeof line, stdin) || strcmp(line, HEADER) != 0) {
        fail("expected the wirecheck-candidate 1 header");
        return 2;
    }
    fputs(HEADER, stdout);
    fflush(stdout);
    while (fgets(line, sizeof line, stdin)) {
        double n_d, K[9], R[9], t[3], near, far;
        if (!numbers(line, "n", &n_d, 1) || !numbers(line, "K", K, 9) || !numbers(line, "R", R, 9)
            || !numbers(line, "t", t, 3) || !numbers(line, "near", &near, 1) || !numbers(line, "far", &far, 1)) {
            fail("request without n, K, R, t, near or far");
            return 2;
        }
        int ortho = strstr(line, "\"projection\":\"orthographic\"") != NULL;
        size_t n = (size_t)n_d;
        double *p = malloc(n * 3 * sizeof(double) + 1), *px = malloc(n * 2 * sizeof(double) + 1);
        if (!p || !px || fread(p, sizeof(double), n * 3, stdin) != n * 3) {
            fprintf(stderr, "candidate.c: could not read %zu points\n", n);
            return 2;
        }
        for (size_t i = 0; i < n; i++) {
            const double *X = p + 3 * i;
            double c[3];
            for (int r = 0; r < 3; r++)
                c[r] = R[3 * r] * X[0] + R[3 * r + 1] * X[1] + R[3 * r + 2] * X[2] + t[r];
            if (!(c[2] >= near && c[2] <= far)) {
                px[2 * i] = px[2 * i + 1] = NAN;
                continue;
            }
            double x = ortho ? c[0] : c[0] / c[2], y = ortho ? c[1] : c[1] / c[2];
            px[2 * i] = K[0] * x + K[1] * y + K[2];
            px[2 * i + 1] = K[4] * y + K[5];
        }
        printf("{\"n\": %zu}\n", n);
        fwrite(px, sizeof(double), n * 2, stdout);
        fflush(stdout);
        free(p);
        free(px);
    }
    return 0;
}

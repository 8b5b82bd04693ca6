/* budget.c - what a dense build will cost, asked before it starts.

   The classic, multibounce, temporal and local methods (and rad formfactors) need at least one
   patch per triangle and a dense N x N form-factor matrix: 4 N^2 bytes, plus what the method
   builds from it. A real scene (the 66k-triangle Sponza: 17.7 GB for F alone, hours of form
   factors) ran without a word until the machine gave out. So before the patches are made
   (N at least the triangle count) and again once N is known, the tool estimates the memory
   and the time, and refuses a build that exceeds the memory limit (--max-memory, else
   /proc/meminfo's MemAvailable) or TOOL_DENSE_MAX_SECONDS, naming the virtual-patch
   methods instead; --force runs it anyway.

   Memory per N^2 entry (the arrays that are alive at the peak): F 4 bytes; the direct solver's
   LU copy 8 (doubles); multibounce 16 of scratch and 12 of result (rad_multibounce_create),
   half-precision 6; temporal alias tables 12 (wide: an upper bound for compact's 8), per
   channel in --mode multibounce; a classic bake writes F twice more (rad_save_memory's buffer
   and the container); local adds 12 M^2 for T. Time: the form factors at
   TOOL_FF_RATE sample pairs per second per thread (measured on the Cornell box: 2188
   patches, 16 samples, 22.6 s on 2 threads), plus N^3 / 3 (LU) or 2 N^3 per squaring
   (multibounce) flops at TOOL_FLOP_RATE per thread: rough, within a factor of a few. */
#include "tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define TOOL_FF_RATE 1.7e6
#define TOOL_FLOP_RATE 2e9

int tool_parse_bytes(const char *cmd, const char *opt, const char *text, double *out)
{
    char *end;
    double v, unit = 1.0;
    if (!text || !*text || *text == '-') goto bad;
    v = strtod(text, &end);
    if (end == text || !(v >= 0.0) || v > 1e30) goto bad;
    switch (*end) {
    case 0: break;
    case 'k': case 'K': unit = 1024.0; ++end; break;
    case 'm': case 'M': unit = 1048576.0; ++end; break;
    case 'g': case 'G': unit = 1073741824.0; ++end; break;
    case 't': case 'T': unit = 1099511627776.0; ++end; break;
    default: goto bad;
    }
    if ((*end == 'i' || *end == 'I') && unit > 1.0) ++end;
    if ((*end == 'b' || *end == 'B') && unit > 1.0) ++end;
    if (*end != 0 || !(v * unit >= 1.0)) goto bad;
    *out = v * unit;
    return 0;
bad:
    fprintf(stderr, "rad %s: bad value '%s' for %s (want bytes > 0, e.g. 512M, 4G or 1.5T; K, M, G, T are powers of 1024)\n",
            cmd, text ? text : "", opt);
    return 2;
}

double tool_mem_available(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    char line[256];
    double kb = 0.0;
    if (!f) return 0.0;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "MemAvailable:", 13)) {
            kb = strtod(line + 13, NULL);
            break;
        }
    fclose(f);
    return kb > 0.0 ? kb * 1024.0 : 0.0;
}

static int threads_now(void)
{
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

static void print_bytes(char *buf, size_t len, double b)
{
    if (b < 1073741824.0) snprintf(buf, len, "%.0f MiB", b / 1048576.0);
    else snprintf(buf, len, "%.1f GiB", b / 1073741824.0);
}

static void print_time(char *buf, size_t len, double s)
{
    if (s < 120.0) snprintf(buf, len, "%.0f s", s);
    else if (s < 7200.0) snprintf(buf, len, "%.0f minutes", s / 60.0);
    else if (s < 172800.0) snprintf(buf, len, "%.1f hours", s / 3600.0);
    else snprintf(buf, len, "%.0f days", s / 86400.0);
}

int tool_dense_check(const char *cmd, const tool_classic_options *o, uint32_t n, int lower_bound)
{
    double N = (double)n, per = o->dense_bytes_per_n2 > 0.0 ? o->dense_bytes_per_n2 : 4.0, bytes, seconds, limit;
    double m = o->dense_local_m ? (N < (double)o->dense_local_m ? N : (double)o->dense_local_m) : 0.0;
    int th = threads_now(), mem_over, time_over;
    const char *limit_from;
    char tbuf[64], bbuf[64], lbuf[64];
    if (o->sources_only && o->no_form_factors) return 0; /* stochastic: no N x N matrix */
    bytes = per * N * N + 12.0 * m * m + 200.0 * N; /* + the patches, vectors and per-patch data */
    seconds = N * N * (double)(o->samples ? o->samples : 16u) / (TOOL_FF_RATE * th) +
              (o->dense_cubic * N * N * N + 6.0 * m * m * m) / (TOOL_FLOP_RATE * th);
    if (o->max_memory > 0.0) limit = o->max_memory, limit_from = "--max-memory";
    else limit = tool_mem_available(), limit_from = "MemAvailable in /proc/meminfo";
    mem_over = limit > 0.0 && bytes > limit;
    time_over = seconds > TOOL_DENSE_MAX_SECONDS;
    print_time(tbuf, sizeof tbuf, seconds);
    print_bytes(bbuf, sizeof bbuf, bytes);
    print_bytes(lbuf, sizeof lbuf, limit);
    if (o->force || (!mem_over && !time_over)) {
        if (!lower_bound && (bytes > 1073741824.0 || seconds > 60.0))
            fprintf(stderr, "rad %s: the dense build of %u patches needs about %s and %s%s\n", cmd, n, bbuf, tbuf, o->force && (mem_over || time_over) ? " (over the limits: --force)" : "");
        return 0;
    }
    fprintf(stderr,
            "rad %s: %s%s need%s a dense %u x %u form-factor matrix (%s%u patches): about %s of memory and "
            "roughly %s (%u form-factor samples per pair on %d threads)",
            cmd, o->dense_method ? "--method " : "the form factors", o->dense_method ? o->dense_method : "",
            o->dense_method ? "s" : "", n, n, lower_bound ? "at least one patch per triangle: " : "", n, bbuf, tbuf,
            o->samples ? o->samples : 16u, th);
    if (mem_over) fprintf(stderr, "; only %s may be used (%s)", lbuf, limit_from);
    if (time_over) fprintf(stderr, "%s more than the %.0f minutes the tool starts a dense build for",
                           mem_over ? ", and" : ";", TOOL_DENSE_MAX_SECONDS / 60.0);
    if (o->dense_instead) {
        fprintf(stderr, ".\nrad %s: use %s, or give --force to build it anyway%s\n", cmd, o->dense_instead,
                mem_over ? " (or --max-memory SIZE for another limit)" : "");
        return 1;
    }
    fprintf(stderr, ".\nrad %s: use %s--method aavp or --method vp (virtual patches: a few thousand patches whatever the "
                    "triangle count; --vp-max-patches B sets how many; --proxy aavp runs multibounce, temporal or local over them), "
                    "or give --force to build it anyway%s\n",
            cmd, o->dense_method ? "" : "rad render ", mem_over ? " (or --max-memory SIZE for another limit)" : "");
    return 1;
}

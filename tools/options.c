/* options.c - command-line options from tables: one row per option names it, says where its
   value goes and what it accepts, and carries its help text, so that a command's parser and
   its --help are the same table and cannot disagree (tool_args_* in tool.h). */
#include "tool.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the column where the help text of an option starts */
#define TOOL_ARG_HELP_COLUMN 21

static const tool_arg *args_find(const tool_arg *table, const char *name)
{
    for (; table->kind != TOOL_ARG_END; ++table)
        if (table->name && !strcmp(table->name, name)) return table;
    return NULL;
}

/* the value of a TOOL_ARG_CHOICE: its index among the '|'-separated names, or -1 */
static int args_choice(const char *choices, const char *v)
{
    size_t n = strlen(v);
    int i = 0;
    const char *p = choices;
    while (*p) {
        const char *e = strchr(p, '|');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && !strncmp(p, v, n)) return i;
        ++i;
        p += len + (e ? 1 : 0);
    }
    return -1;
}

/* "a|b|c" as "a, b or c" */
static void args_choice_list(const char *choices, char *out, size_t size)
{
    size_t k = 0, i, bars = 0, seen = 0;
    for (i = 0; choices[i]; ++i) bars += choices[i] == '|';
    for (i = 0; choices[i] && k + 5 < size; ++i) {
        if (choices[i] != '|') { out[k++] = choices[i]; continue; }
        ++seen;
        if (seen == bars) { memcpy(out + k, " or ", 4); k += 4; }
        else { memcpy(out + k, ", ", 2); k += 2; }
    }
    out[k] = '\0';
}

static int args_value(const char *cmd, const tool_arg *t, const char *v, void *target)
{
    char *field = (char *)target + t->field;
    switch (t->kind) {
    case TOOL_ARG_UINT: {
        uint32_t x;
        if (tool_parse_uint(cmd, t->name, v, &x)) return 2;
        if ((double)x < t->lo || (double)x > t->hi) {
            fprintf(stderr, "rad %s: %s %s, not %s\n", cmd, t->name, t->bad, v);
            return 2;
        }
        memcpy(field, &x, sizeof x);
        return 0;
    }
    case TOOL_ARG_FLOAT: {
        float x;
        int low;
        if (tool_parse_float(cmd, t->name, v, &x)) return 2;
        low = (t->flags & TOOL_ARG_LO_OPEN) ? !((double)x > t->lo) : !((double)x >= t->lo);
        if (low || ((t->flags & TOOL_ARG_HI_OPEN) ? !((double)x < t->hi) : !((double)x <= t->hi))) {
            fprintf(stderr, "rad %s: %s %s, not %s\n", cmd, t->name, t->bad, v);
            return 2;
        }
        memcpy(field, &x, sizeof x);
        return 0;
    }
    case TOOL_ARG_STRING:
        if (!*v && (t->flags & TOOL_ARG_NONEMPTY)) {
            fprintf(stderr, "rad %s: %s %s\n", cmd, t->name, t->bad);
            return 2;
        }
        memcpy(field, &v, sizeof v);
        return 0;
    case TOOL_ARG_CHOICE: {
        int i = args_choice(t->choices, v);
        uint32_t x;
        if (i < 0) {
            char list[256];
            args_choice_list(t->choices, list, sizeof list);
            fprintf(stderr, "rad %s: unknown %s '%s' (%s)\n", cmd, t->name, v, list);
            return 2;
        }
        x = t->values ? t->values[i] : (uint32_t)i;
        memcpy(field, &x, sizeof x);
        return 0;
    }
    default:
        return t->parse(cmd, t, v, field);
    }
}

int tool_args_parse(const char *cmd, const tool_arg *table, void *target, uint32_t *given, int argc, char **argv, int *a)
{
    const tool_arg *t = args_find(table, argv[*a]);
    if (!t) return 0;
    if (t->kind == TOOL_ARG_FLAG) {
        int x = (int)t->lo;
        memcpy((char *)target + t->field, &x, sizeof x);
    } else {
        if (*a + 1 >= argc) {
            fprintf(stderr, "rad %s: %s needs a value\n", cmd, argv[*a]);
            return 2;
        }
        ++*a;
        if (args_value(cmd, t, argv[*a], target)) return 2;
    }
    if (given) *given |= t->given;
    return 1;
}

/* appends to buf (size bytes, kept terminated) */
static void args_put(char *buf, size_t size, size_t *n, const char *text, size_t len)
{
    if (*n + len >= size) len = *n + 1 < size ? size - 1 - *n : 0;
    memcpy(buf + *n, text, len);
    *n += len;
    buf[*n] = '\0';
}

void tool_args_help_into(const tool_arg *table, unsigned where, char *buf, size_t size)
{
    static const char pad[] = "                                ";
    size_t n = 0;
    buf[0] = '\0';
    for (; table->kind != TOOL_ARG_END; ++table) {
        const char *h = table->help;
        size_t col;
        if (where && table->where && !(table->where & where)) continue;
        if (table->kind == TOOL_ARG_TEXT) {
            args_put(buf, size, &n, h, strlen(h));
            continue;
        }
        args_put(buf, size, &n, "  ", 2);
        args_put(buf, size, &n, table->name, strlen(table->name));
        col = 2 + strlen(table->name);
        if (table->value) {
            args_put(buf, size, &n, " ", 1);
            args_put(buf, size, &n, table->value, strlen(table->value));
            col += 1 + strlen(table->value);
        }
        /* the text from its column, or two spaces past a long name */
        args_put(buf, size, &n, pad, col + 2 < TOOL_ARG_HELP_COLUMN ? TOOL_ARG_HELP_COLUMN - col : 2);
        while (*h) {
            const char *e = strchr(h, '\n');
            size_t len = e ? (size_t)(e - h) : strlen(h);
            args_put(buf, size, &n, h, len);
            args_put(buf, size, &n, "\n", 1);
            h += len + (e ? 1 : 0);
            if (*h) args_put(buf, size, &n, pad, TOOL_ARG_HELP_COLUMN);
        }
    }
}

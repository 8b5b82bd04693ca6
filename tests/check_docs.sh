#!/usr/bin/env bash
# Checks that what is written twice stays the same: "api" compares docs/api.md with what
# tools/api_index.awk makes of radiosity.h; "quickstart" compares the header's QUICK START
# comment with examples/quickstart.c (whitespace-normalised, the file's opening comment aside);
# "defaults" checks that tests/test_defaults.c covers every rad_*_options_default of the header.
# Exits non-zero and prints the difference and the command that fixes it.
set -u
cd "$(dirname "$0")/.."
what=${1:-all}
rc=0
# every run of blanks made one space, blank lines dropped
norm() { sed 's/[[:space:]]\{1,\}/ /g; s/^ //; s/ $//' | grep -v '^$'; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

if [ "$what" = all ] || [ "$what" = api ]; then
    awk -f tools/api_index.awk docs/api.md radiosity.h radiosity.h >"$tmp/api.md"
    if ! diff -u docs/api.md "$tmp/api.md" >"$tmp/api.diff"; then
        head -40 "$tmp/api.diff"
        echo "docs/api.md is not the index of radiosity.h: run 'make api' and commit docs/api.md"
        rc=1
    fi
fi

if [ "$what" = all ] || [ "$what" = quickstart ]; then
    awk '/^   QUICK START/ { q = 1; next } /^   CONTENTS/ { q = 0 } q' radiosity.h | norm >"$tmp/header.c"
    # the file's own opening comment is not in the header
    awk 'NR == 1 && /^\/\*/ { c = 1 } c { if (index($0, "*/")) c = 0; next } { print }' examples/quickstart.c | norm >"$tmp/file.c"
    if [ ! -s "$tmp/header.c" ]; then
        echo "radiosity.h has no QUICK START block (between '   QUICK START' and '   CONTENTS')"
        rc=1
    elif ! diff -u "$tmp/header.c" "$tmp/file.c" >"$tmp/qs.diff"; then
        head -40 "$tmp/qs.diff"
        echo "the QUICK START comment of radiosity.h differs from examples/quickstart.c (- header, + file): make them the same"
        rc=1
    fi
fi
if [ "$what" = all ] || [ "$what" = defaults ]; then
    grep -o '^RAD_API void rad_[a-z0-9_]*_options_default(' radiosity.h | sed 's/^RAD_API void //; s/($//' | sort -u >"$tmp/header.list"
    grep -o '"rad_[a-z0-9_]*_options_default"' tests/test_defaults.c | tr -d '"' | sort -u >"$tmp/test.list"
    missing=$(comm -23 "$tmp/header.list" "$tmp/test.list")
    if [ ! -s "$tmp/header.list" ]; then
        echo "radiosity.h declares no rad_*_options_default (the pattern no longer matches)"
        rc=1
    elif [ -n "$missing" ]; then
        echo "tests/test_defaults.c does not cover:" $missing
        echo "add each to df_covered there with a test that runs its consumer on a zeroed struct and on the _default one"
        rc=1
    fi
fi
exit $rc

# docs/api.md from radiosity.h: every public declaration of the header, grouped by its >>api_*
# sections in header order, each with the first sentence of the comment above it.
#   awk -f tools/api_index.awk docs/api.md radiosity.h radiosity.h > docs/api.md.new
# (make api does this). The first file gives the hand-written introduction: everything above
# the line MARK is copied unchanged. The header is read twice: the first pass finds which
# structs have a body (a forward typedef of one of those is not listed on its own), the second
# writes the index. Plain POSIX awk (mawk, gawk, busybox).

BEGIN {
    MARK = "<!-- Everything below is generated from radiosity.h by make api; edit the header, not this. -->"
    file = 0
}

FNR == 1 { file++; in_comment = 0; depth = 0; api = 0 }

# ---- file 1: the introduction ------------------------------------------------------------
file == 1 {
    if ($0 == MARK) intro_done = 1
    if (!intro_done) intro = intro $0 "\n"
    next
}

# ---- the two passes over the header: comments split from code, line by line ------------
{
    code = ""; comment = ""; line = $0; comment_start = 0
    while (length(line) > 0) {
        if (in_comment) {
            e = index(line, "*/")
            if (e == 0) { comment = comment " " line; line = ""; break }
            comment = comment " " substr(line, 1, e - 1); line = substr(line, e + 2); in_comment = 0
        } else {
            s = index(line, "/*")
            if (s == 0) { code = code line; line = "" ; break }
            if (code == "" && s == 1) comment_start = 1
            code = code substr(line, 1, s - 1); line = substr(line, s + 2); in_comment = 1
        }
    }
}

# the compile-time macros users set: the OPTIONS table of the header's doc block, kept as it is
file == 3 && /^   1\. OPTIONS/ { in_options = 1; next }
file == 3 && /^   2\. / { in_options = 0 }
file == 3 && in_options { o = $0; sub(/^       /, "", o); options = options o "\n"; next }

# the declarations run from the first >>api_ section to the end of the include guard
/^\/\* >>api_[a-z0-9_]+: / { api = 1 }
/^#endif \/\* RADIOSITY_H \*\// { api = 0 }
!api { next }

file == 2 {
    if (depth == 0 && match(code, /^(typedef[ \t]+)?struct[ \t]+[A-Za-z_0-9]+[ \t]*\{/)) {
        n = code; sub(/^(typedef[ \t]+)?struct[ \t]+/, "", n); sub(/[ \t]*\{.*/, "", n)
        has_body[n] = 1
    }
    depth += count_char(code, "{") - count_char(code, "}")
    next
}

# ---- file 3: the index -------------------------------------------------------------------
{
    at_depth = depth
    depth += count_char(code, "{") - count_char(code, "}")
}

/^\/\* >>api_[a-z0-9_]+: / {
    t = $0; sub(/^\/\* >>api_/, "", t); sub(/[ \t]*\*\/[ \t]*$/, "", t)
    name = t; sub(/:.*/, "", name); title = t; sub(/^[^:]*:[ \t]*/, "", title)
    flush_row()
    sections++; sec_name[sections] = name; sec_title[sections] = title; sec_rows[sections] = 0
    attached = ""; collecting = 0
    next
}

# a blank line ends what a comment describes
/^[ \t]*$/ { if (!collecting) { flush_row(); attached = "" } ; next }

# the ruled lines around a section title
/^\/\* =+ \*\/$/ { next }

at_depth == 0 {
    # a top-level comment (not a trailing one) describes what follows it
    if (comment_start && trim(code) == "") {
        if (!collecting) { flush_row(); attached = "" }
        attached = attached comment
        collecting = in_comment
        next
    }
    if (collecting) { attached = attached comment; collecting = in_comment; next }
    c = trim(code)
    if (c ~ /^#/) {
        if (c ~ /^#define[ \t]+RAD_[A-Za-z0-9_]*/ && c !~ /^#define[ \t]+RAD__/) {
            n = c; sub(/^#define[ \t]+/, "", n); sub(/[^A-Za-z0-9_].*$/, "", n)
            if (n == "RAD_API") next
            if (n ~ /\(/ || c ~ /^#define[ \t]+[A-Za-z0-9_]+\(/) n = n "()"
            add(n, "macro", comment)
        }
        next
    }
    if (c ~ /^RAD_API[ \t]/) {
        n = c; sub(/\(.*/, "", n); sub(/.*[^A-Za-z0-9_]/, "", n)
        add(n, "function", comment)
        next
    }
    if (c ~ /^typedef[ \t]+(struct|enum|union)[ \t]+[A-Za-z0-9_]+[ \t]+[A-Za-z0-9_]+[ \t]*;/) {
        n = c; sub(/^typedef[ \t]+(struct|enum|union)[ \t]+/, "", n); sub(/[ \t].*/, "", n)
        if (!has_body[n]) add(n, "type", comment)
        next
    }
    if (c ~ /^typedef[ \t]+enum/) { n = c; sub(/^typedef[ \t]+enum[ \t]*/, "", n); sub(/[^A-Za-z0-9_].*/, "", n)
        add(n, "enum", comment); next }
    if (c ~ /^typedef[ \t]+(struct|union)/) { n = c; sub(/^typedef[ \t]+(struct|union)[ \t]*/, "", n); sub(/[^A-Za-z0-9_].*/, "", n)
        add(n, "struct", comment); next }
    if (c ~ /^(struct|union)[ \t]+[A-Za-z0-9_]+[ \t]*\{/) { n = c; sub(/^(struct|union)[ \t]+/, "", n); sub(/[^A-Za-z0-9_].*/, "", n)
        add(n, "struct", comment); next }
    if (c ~ /^typedef[ \t].*\(\*[ \t]*[A-Za-z0-9_]+[ \t]*\)/) {
        n = c; sub(/^[^(]*\(\*[ \t]*/, "", n); sub(/[^A-Za-z0-9_].*/, "", n)
        add(n, "callback", comment); next
    }
    if (c ~ /^typedef[ \t]/) { n = c; sub(/[ \t]*;.*/, "", n); sub(/.*[^A-Za-z0-9_]/, "", n); add(n, "type", comment); next }
}

END {
    flush_row()
    printf "%s", intro
    print MARK
    print ""
    print "## Compile-time options"
    print ""
    print "Macros you define before including the header (from its OPTIONS table):"
    print ""
    print "```"
    sub(/\n+$/, "\n", options)
    printf "%s", options
    print "```"
    print ""
    print "## Sections"
    print ""
    print "| section | what it holds |"
    print "| --- | --- |"
    for (s = 1; s <= sections; s++) printf "| [%s](#api_%s) | %s |\n", sec_name[s], sec_name[s], esc(sec_title[s])
    for (s = 1; s <= sections; s++) {
        print ""
        printf "<a id=\"api_%s\"></a>\n\n", sec_name[s]
        printf "## %s: %s\n\n", sec_name[s], sec_title[s]
        printf "Header anchor `>>api_%s`.\n\n", sec_name[s]
        print "| declaration | kind | purpose |"
        print "| --- | --- | --- |"
        for (r = 1; r <= sec_rows[s]; r++) print row[s, r]
    }
}

# ---- helpers -----------------------------------------------------------------------------
function count_char(s, ch,    n, i) { n = 0; while ((i = index(s, ch)) > 0) { n++; s = substr(s, i + 1) } ; return n }
function trim(s) { sub(/^[ \t]+/, "", s); sub(/[ \t]+$/, "", s); return s }
function esc(s) { gsub(/\|/, "\\|", s); return s }

# the first sentence of a comment, on one line
function first_sentence(s,    out, i, ch, nx) {
    gsub(/[ \t]+/, " ", s); s = trim(s)
    out = ""
    for (i = 1; i <= length(s); i++) {
        ch = substr(s, i, 1); out = out ch
        if (ch == ".") {
            nx = substr(s, i + 1, 2)
            if (nx == "" || nx ~ /^ [^ 0-9]/) {
                # not an abbreviation's dot ("e.g. X", "i.e. X", "vs. X")
                if (out !~ /(e\.g|i\.e|vs|etc|cf|al)\.$/) break
            }
        }
    }
    return out
}

# a declaration: joins the row of the comment it shares with the one before, else starts one
function add(name, kind, trailing,    purpose) {
    if (seen[name]) return
    seen[name] = 1
    if (attached != "" && row_open) {
        row_names = row_names ", `" name "`"
        if (row_kind != kind) row_kind = row_kind ", " kind
        return
    }
    flush_row()
    purpose = attached != "" ? attached : trailing
    row_names = "`" name "`"; row_kind = kind; row_purpose = first_sentence(purpose); row_open = 1
    if (attached == "") flush_row()
}

function flush_row() {
    if (!row_open) return
    sec_rows[sections]++
    row[sections, sec_rows[sections]] = "| " row_names " | " row_kind " | " esc(row_purpose) " |"
    row_open = 0
}

# svgplot.awk - a small SVG line plot, written for tools/report.sh (no plotting package needed).
#
#   awk -v title=T -v xlabel=X -v ylabel=Y [-v logx=1] [-v logy=1] [-v markers=1] \
#       -f tools/svgplot.awk DATA > OUT.svg
#
# DATA: whitespace-separated columns; the first line names them (the first column is x, each
# further column one series; an underscore in a name is shown as a space). A value that is not a
# number ('-', 'nan') is skipped (the line joins the points on either side, so series measured at
# different x can share one file). Log axes skip values <= 0. Ticks: decades (and 2, 5) on log
# axes, 1/2/5 x 10^k steps on linear ones.

function fmt(v,    a) {
    a = v < 0 ? -v : v
    if (v == 0) return "0"
    if (a >= 1e5 || a < 1e-3) return sprintf("%.0e", v)
    return sprintf("%.6g", v)
}
function tx(v) { return ML + (logx ? (log(v) - lx0) / (lx1 - lx0) : (v - lx0) / (lx1 - lx0)) * PW }
function ty(v) { return MT + PH - (logy ? (log(v) - ly0) / (ly1 - ly0) : (v - ly0) / (ly1 - ly0)) * PH }
function isnum(s) { return s ~ /^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$/ }
function esc(s) { gsub(/&/, "\\&amp;", s); gsub(/</, "\\&lt;", s); gsub(/>/, "\\&gt;", s); return s }
# linear ticks between a and b: a 1/2/5 x 10^k step giving 4 to 10 ticks
function lin_step(a, b,    span, st, m) {
    span = b - a
    if (span <= 0) return 1
    st = exp(log(10) * int(log(span / 5) / log(10) + (span / 5 < 1 ? -1 : 0)))
    for (m = 0; m < 3 && span / st > 10; ++m) st *= (m == 0 ? 2 : m == 1 ? 2.5 : 2)
    return st
}
NR == 1 { ncol = NF; for (i = 1; i <= NF; ++i) { name[i] = $i; gsub(/_/, " ", name[i]) } next }
{
    ++nrow
    for (i = 1; i <= ncol; ++i) val[nrow, i] = $i
}
END {
    W = 700; H = 400; ML = 78; MR = 230; MT = 36; MB = 52; PW = W - ML - MR; PH = H - MT - MB
    split("#1f77b4 #d62728 #2ca02c #ff7f0e #9467bd #8c564b #e377c2 #17becf", colour, " ")
    xmin = ymin = 1e300; xmax = ymax = -1e300
    for (r = 1; r <= nrow; ++r) {
        x = val[r, 1]
        if (!isnum(x) || (logx && x + 0 <= 0)) continue
        x += 0
        for (i = 2; i <= ncol; ++i) {
            y = val[r, i]
            if (!isnum(y) || (logy && y + 0 <= 0)) continue
            y += 0
            if (x < xmin) xmin = x; if (x > xmax) xmax = x
            if (y < ymin) ymin = y; if (y > ymax) ymax = y
        }
    }
    if (xmin > xmax) { xmin = 0; xmax = 1; ymin = 0; ymax = 1; empty = 1 }
    if (xmax == xmin) { xmin = logx ? xmin / 2 : xmin - 1; xmax = logx ? xmax * 2 : xmax + 1 }
    if (ymax == ymin) { ymin = logy ? ymin / 2 : ymin - 1; ymax = logy ? ymax * 2 : ymax + 1 }
    if (logx) { lx0 = log(xmin); lx1 = log(xmax) } else { lx0 = xmin; lx1 = xmax }
    if (logy) {
        ly0 = log(10) * int(log(ymin) / log(10) - (ymin < 1 ? 1 : 0) + 1e-9)
        ly1 = log(10) * (int(log(ymax) / log(10) - (ymax < 1 ? 1 : 0) + 1e-9) + 1)
        if (ly1 - ly0 > log(10) * 1.01 && log(ymax) < ly1 - log(10) + 1e-9) ly1 -= log(10)
    } else {
        st = lin_step(ymin < 0 ? ymin : 0, ymax)
        ly0 = ymin < 0 ? st * int(ymin / st - 1) : 0
        ly1 = st * int(ymax / st + 0.999999)
        if (ly1 <= ly0) ly1 = ly0 + st
    }
    if (!logx) { sx = lin_step(xmin, xmax); lx0 = sx * int(xmin / sx + (xmin < 0 ? -1 : 0)); lx1 = sx * int(xmax / sx + 0.999999); if (lx1 <= lx0) lx1 = lx0 + sx }
    printf("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" font-family=\"sans-serif\" font-size=\"12\">\n", W, H, W, H)
    printf("<rect width=\"%d\" height=\"%d\" fill=\"white\"/>\n", W, H)
    printf("<text x=\"%d\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">%s</text>\n", ML + PW / 2, esc(title))
    # grid and ticks
    if (logy) {
        for (e = int(ly0 / log(10) + (ly0 < 0 ? -0.5 : 0.5)); log(10) * e <= ly1 + 1e-9; ++e)
            for (m = 1; m <= 5; m += (m == 1 ? 1 : 3)) {
                v = m * exp(log(10) * e)
                if (log(v) < ly0 - 1e-9 || log(v) > ly1 + 1e-9) continue
                y = ty(v)
                printf("<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"%s\"/>\n", ML, y, ML + PW, y, m == 1 ? "#ccc" : "#eee")
                printf("<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">%s</text>\n", ML - 6, y + 4, fmt(v))
            }
    } else {
        st = lin_step(ly0, ly1)
        for (v = ly0; v <= ly1 + st * 1e-6; v += st) {
            y = ty(v)
            printf("<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", ML, y, ML + PW, y)
            printf("<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">%s</text>\n", ML - 6, y + 4, fmt(v))
        }
    }
    if (logx) {
        nt = 0
        for (e = int(lx0 / log(10) - 1); log(10) * e <= lx1 + 1e-9; ++e)
            for (m = 1; m <= 5; m += (m == 1 ? 1 : 3)) {
                v = m * exp(log(10) * e)
                if (log(v) < lx0 - 1e-9 || log(v) > lx1 + 1e-9) continue
                ++nt
                x = tx(v)
                printf("<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#ddd\"/>\n", x, MT, x, MT + PH)
                printf("<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", x, MT + PH + 16, fmt(v))
            }
        if (nt < 2)
            for (k = 0; k < 2; ++k) {
                v = k ? xmax : xmin
                printf("<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", tx(v), MT + PH + 16, fmt(v))
            }
    } else {
        for (v = lx0; v <= lx1 + sx * 1e-6; v += sx) {
            x = tx(v)
            printf("<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#ddd\"/>\n", x, MT, x, MT + PH)
            printf("<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", x, MT + PH + 16, fmt(v))
        }
    }
    printf("<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"black\"/>\n", ML, MT, PW, PH)
    printf("<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", ML + PW / 2, H - 12, esc(xlabel))
    printf("<text transform=\"translate(16 %d) rotate(-90)\" text-anchor=\"middle\">%s</text>\n", MT + PH / 2, esc(ylabel))
    if (empty) printf("<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">no data</text>\n", ML + PW / 2, MT + PH / 2)
    # series
    for (i = 2; i <= ncol; ++i) {
        c = colour[(i - 2) % 8 + 1]
        path = ""
        pen = 0
        for (r = 1; r <= nrow; ++r) {
            x = val[r, 1]; y = val[r, i]
            if (!isnum(x) || !isnum(y) || (logx && x + 0 <= 0) || (logy && y + 0 <= 0)) continue
            path = path sprintf("%s%.1f %.1f ", pen ? "L" : "M", tx(x + 0), ty(y + 0))
            pen = 1
            if (markers) mk = mk sprintf("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n", tx(x + 0), ty(y + 0), c)
        }
        if (path != "") printf("<path d=\"%s\" fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\"/>\n", path, c)
        printf("%s", mk); mk = ""
        ly = MT + 10 + (i - 2) * 18
        printf("<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"%s\" stroke-width=\"2\"/>\n", ML + PW + 10, ly, ML + PW + 30, ly, c)
        printf("<text x=\"%d\" y=\"%d\">%s</text>\n", ML + PW + 35, ly + 4, esc(name[i]))
    }
    printf("</svg>\n")
}

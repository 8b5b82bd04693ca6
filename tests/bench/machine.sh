# machine.sh - sourced by the shell benchmarks: bench_machine prints the line each section of
# docs/BENCHMARKS.md carries under its heading (CPU model, logical CPUs, load average at the
# start, date), the same line as emit_machine() of bench_common.h.
bench_machine() {
    local model cpus load
    model=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1)
    cpus=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo -1)
    load=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo -1)
    printf 'Machine: %s, %s logical CPUs, load average %.1f at the start; %s.\n\n' \
        "${model:-unknown CPU}" "$cpus" "$load" "$(date -u '+%Y-%m-%d %H:%M UTC')"
}

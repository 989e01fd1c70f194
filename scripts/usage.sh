# Sourced by the bash scripts in scripts/: `usage_on_help "$@"` prints the calling script's
# header comment (what it does and its usage) and exits 0 when -h or --help is among the
# arguments, before anything is installed, built or run. USAGE_BINARY, if set: a compiled tool (a path
# from the repository's root) whose own --help follows when it is built (else a line says how to get it).
usage_on_help() {
    local a bin
    for a in "$@"; do
        [ "$a" = -- ] && return 0
        case "$a" in
            -h|--help)
                sed -n '2,/^[^#]/{/^#/{s/^# \{0,1\}//;p}}' "$0"
                if [ -n "${USAGE_BINARY:-}" ]; then
                    echo
                    bin="$(dirname "$(readlink -f "$0")")/../$USAGE_BINARY"
                    if [ -x "$bin" ]; then "$bin" --help || true
                    else echo "(every option: $USAGE_BINARY --help, once the first run of $0 has compiled it)"; fi
                fi
                exit 0;;
        esac
    done
}

# Shared by the tools' CLI tests: a scratch folder `work` removed on exit, a failure counter,
# and expect_error. Source it after setting `tool` to the executable under test.

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect_error NAME STATUS PATTERN -- ARGS...: `tool ARGS` exits STATUS with one stderr line
# matching PATTERN.
expect_error() {
    local name=$1 status=$2 pattern=$3
    shift 4
    "$tool" "$@" >"$work/out" 2>"$work/err"
    local got=$?
    [ "$got" -eq "$status" ] || fail "$name: exit $got, expected $status"
    [ "$(wc -l <"$work/err")" -eq 1 ] || fail "$name: stderr is not one line: $(cat "$work/err")"
    grep -q -- "$pattern" "$work/err" || fail "$name: stderr lacks '$pattern': $(cat "$work/err")"
}

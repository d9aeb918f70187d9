# What the CLI test scripts share: a temporary directory removed on exit,
# and check / expect_exit, which count checks and failures. Sourced (POSIX sh).
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
checks=0
check() { # description, then a command that must succeed
    desc=$1; shift
    checks=$((checks + 1))
    if ! "$@"; then echo "FAILED: $desc"; fails=$((fails + 1)); fi
}
expect_exit() { # code, command... (stdout and stderr go to $tmp/out and $tmp/err)
    want=$1; shift
    "$@" >"$tmp/out" 2>"$tmp/err"
    got=$?
    [ "$got" = "$want" ] || { echo "exit $got, expected $want: $*"; cat "$tmp/err"; return 1; }
}
expect_exit_not() { # code, command...: any exit but that one (and not timeout's 124)
    unwanted=$1; shift
    "$@" >"$tmp/out" 2>"$tmp/err"
    got=$?
    [ "$got" != "$unwanted" ] && [ "$got" != 124 ] || { echo "exit $got: $*"; cat "$tmp/err"; return 1; }
}

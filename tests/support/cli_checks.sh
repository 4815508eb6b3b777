# Shared helpers of the shell tests that drive the surge executable (tests/unit/app/*.sh,
# tests/verification/column_impact_sweep_test.sh). Source it after `set -u`; it counts results in
# $pass and $fail and makes a scratch folder $work, removed on exit.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
pass=0

ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; fail=$((fail + 1)); }

expect() {  # expect <name> <expected exit code> <regex on combined output> -- command...
  local name=$1 code=$2 regex=$3
  shift 4
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -ne "$code" ]; then
    bad "$name: exit $rc, expected $code"; echo "$out" | tail -8; return
  fi
  if ! grep -Eq -- "$regex" <<<"$out"; then
    bad "$name: output does not match /$regex/"; echo "$out" | tail -8; return
  fi
  ok "$name"
}

finish() {  # finish [label]: prints the tally; the script's exit status is 0 only if nothing failed
  echo "${1:+$1: }$pass passed, $fail failed"
  [ "$fail" -eq 0 ]
}

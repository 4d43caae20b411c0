# Shared by the command-line tests (sourced; needs $work and $failures):
# expect CODE PATTERN -- command...: exit code CODE and stderr matching
# PATTERN (an extended regex; "" for any stderr). fail MESSAGE counts a failure.
expect() {
  local code=$1 pattern=$2
  shift 3
  "$@" >"$work/out" 2>"$work/err"
  local got=$?
  if [ "$got" -ne "$code" ] || { [ -n "$pattern" ] && ! grep -Eq -- "$pattern" "$work/err"; }; then
    echo "FAIL: $* -> exit $got (want $code), stderr:" >&2
    head -c 4000 "$work/err" >&2
    failures=$((failures + 1))
  else
    echo "ok: $*"
  fi
}
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# Sourced by summary_same.sh and summary_less.sh.
# summary_values "COMMAND" KEY...: runs COMMAND and prints the values of KEYs on its last `summary` line,
# space-separated. Returns 1, having printed why (and the output's tail), when the command exits
# non-zero, prints no summary line, or a key's value is missing or not a number.
summary_values() {
  local cmd=$1 out rc line k v vals=""
  shift
  out=$($cmd 2>&1); rc=$?
  line=$(printf '%s\n' "$out" | grep '^summary ' | tail -n 1)
  if [ $rc -ne 0 ] || [ -z "$line" ]; then printf '%s\n' "$out" | tail -n 20; echo "FAIL: '$cmd' exited with $rc / no summary"; return 1; fi
  for k in "$@"; do
    v=$(printf '%s\n' "$line" | tr ' ' '\n' | grep "^$k=" | cut -d= -f2)
    [[ $v =~ ^[-+]?[0-9.]+([eE][-+]?[0-9]+)?$ ]] || { echo "FAIL: '$cmd': $k is '${v}', not a number"; return 1; }
    vals="$vals $v"
  done
  echo "$vals"
}

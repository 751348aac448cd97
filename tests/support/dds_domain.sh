# tests/support/dds_domain.sh: the DDS domains a shell test uses (source it; bash), held as the
# C++ tests hold theirs (dyad/testing/dds_domain.hpp: an flock on /tmp/dyad-test-domains/D.lock),
# so that tests running at once never share one.
#
#   claim_test_domains N VAR   sets VAR (a name not starting with _) to the first of N consecutive domains in 1..200 that no
#                              other test holds; this shell holds them (descriptors it keeps open,
#                              and the processes it starts inherit) until they all end. Call it in
#                              the script's own shell, not in $(...), whose shell ends at once.
claim_test_domains() {
  # Locals are prefixed: printf -v would set a local of the caller's VAR's name, not the caller's.
  local _n=$1 _var=$2 _dir=/tmp/dyad-test-domains _span _start _i _first _d _fd _held
  mkdir "$_dir" 2> /dev/null && chmod 1777 "$_dir"  # any user's tests may take domains
  _span=$((200 - _n + 1))
  _start=$(($$ % _span))
  for ((_i = 0; _i < _span; _i++)); do
    _first=$((1 + (_start + _i) % _span))
    _held=()
    for ((_d = _first; _d < _first + _n; _d++)); do
      [ -e "$_dir/$_d.lock" ] || { : > "$_dir/$_d.lock"; } 2> /dev/null || true
      exec {_fd}< "$_dir/$_d.lock" || break
      if ! flock -n "$_fd"; then
        exec {_fd}>&-
        break
      fi
      _held+=("$_fd")
    done
    if [ "${#_held[@]}" = "$_n" ]; then
      printf -v "$_var" '%s' "$_first"
      return 0
    fi
    for _fd in "${_held[@]}"; do exec {_fd}>&-; done
  done
  echo "dyad test: no $_n free DDS domain(s) in 1..200 ($_dir): sharing $((1 + _start))" >&2
  printf -v "$_var" '%s' $((1 + _start))
}

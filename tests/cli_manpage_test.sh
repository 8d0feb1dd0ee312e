#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The manual page and the bash completion made from --help (scripts/manpage.sh): every command and
# every option of its --help is in both, the page renders, completion completes commands and
# options. Usage: cli_manpage_test.sh VERDANT_BINARY SOURCE_DIR BUILD_DIR
B=${3:-}
source "$(dirname "$0")/cli_lib.sh" cli_manpage "$1" "$2"
B=${B:-$T}
if [ -f "$B/verdant.1" ] && [ -f "$B/verdant.bash" ]; then ok "made by the build"; else bad "made by the build ($B/verdant.1, $B/verdant.bash)"; fi
# made again here, from this binary: the build's copies are the same text
expect "scripts/manpage.sh" 0 bash "$SRC/scripts/manpage.sh" "$V" "$T"
if cmp -s "$T/verdant.1" "$B/verdant.1" && cmp -s "$T/verdant.bash" "$B/verdant.bash"; then ok "the build's copies are current"; else bad "the build's copies are current"; fi
mapfile -t cmds < <("$V" --help | sed -n '/^commands:/,/^$/p' | sed -n 's/^  \([a-z][a-z-]*\)  .*/\1/p')
[ ${#cmds[@]} -ge 8 ] && ok "${#cmds[@]} commands" || bad "commands in --help (${#cmds[@]})"
source "$T/verdant.bash"
complete_words() { COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); COMPREPLY=(); _verdant; printf '%s\n' "${COMPREPLY[@]}"; }
for c in "${cmds[@]}" "sim --grow"; do
  # shellcheck disable=SC2086
  opts=$("$V" $c --help | grep -oE '^ +(-[a-zA-Z], )?--[a-z0-9-]+' | tr ',' '\n' | tr -d ' ' | sort -u)
  missing_man="" missing_comp=""
  comp=$(complete_words verdant ${c%% *} -)
  for o in $opts; do
    grep -qF -- "$o" "$T/verdant.1" || missing_man="$missing_man $o"
    printf '%s\n' "$comp" | grep -qxF -- "$o" || missing_comp="$missing_comp $o"
  done
  [ -z "$missing_man" ] && ok "$c: every option in the page" || bad "$c: not in the page:$missing_man"
  [ -z "$missing_comp" ] && ok "$c: every option completes" || bad "$c: not completed:$missing_comp"
  grep -q "^\.SS verdant $c\$" "$T/verdant.1" && ok "$c: a section" || bad "$c: a section"
done
[ "$(complete_words verdant gr)" = grow ] && ok "completes a command" || bad "completes a command ($(complete_words verdant gr))"
complete_words verdant sim --wind-f | grep -qx -- --wind-file && ok "completes an option" || bad "completes an option"
complete_words verdant help ha | grep -qx harvest && ok "completes help's command" || bad "completes help's command"
if command -v man >/dev/null; then
  MANWIDTH=100 man -l "$T/verdant.1" >"$T/page" 2>"$T/err" && grep -q "verdant harvest" "$T/page" && ok "the page renders" || bad "the page renders ($(head -c 300 "$T/err"))"
else
  echo "skip rendering the page: man is not installed"
fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]

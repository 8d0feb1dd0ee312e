#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The manual page (verdant.1) and the bash completion (verdant.bash) of the verdant command, made
# from the command's own --help text at build time, so that neither is a second copy to keep by
# hand: `scripts/manpage.sh BUILD/verdant OUTDIR` (CMake runs it; `make install` installs both).
set -eu
V=$1
out=$2
mkdir -p "$out"
# the commands: the lines "  NAME  text" of the main help's "commands:" block
main=$("$V" --help)
mapfile -t cmds < <(printf '%s\n' "$main" | sed -n '/^commands:/,/^$/p' | sed -n 's/^  \([a-z][a-z-]*\)  .*/\1/p')
[ ${#cmds[@]} -gt 0 ] || { echo "manpage: no commands in '$V --help'" >&2; exit 1; }
version=$("$V" --version | sed 's/^verdant //')

# roff: text as it is (no fill), backslashes and leading dots or quotes escaped
roff() { sed -e 's/\\/\\e/g' -e "s/^\\([.']\\)/\\\\\\&\\1/"; }
# the options a help text lists: "  -o, --output", "      --seed" at the start of a line
options() { grep -oE '^ +(-[a-zA-Z], )?--[a-z0-9-]+' | tr ',' '\n' | tr -d ' ' | sort -u | tr '\n' ' '; }

{
  echo ".TH VERDANT 1 \"\" \"verdant $version\" \"User Commands\""
  echo ".SH NAME"
  echo "verdant \\- virtual plants: L-systems grown into labelled geometry, physics, point clouds"
  echo ".SH SYNOPSIS"
  echo ".B verdant"
  echo "\\fIcommand\\fR [\\fIoptions\\fR]"
  echo ".SH DESCRIPTION"
  echo ".nf"
  printf '%s\n' "$main" | roff
  echo ".fi"
  echo ".SH COMMANDS"
  for c in "${cmds[@]}"; do
    echo ".SS verdant $c"
    echo ".nf"
    "$V" "$c" --help | roff
    echo ".fi"
    if [ "$c" = sim ]; then
      echo ".SS verdant sim --grow"
      echo ".nf"
      "$V" sim --grow --help | roff
      echo ".fi"
    fi
  done
  echo ".SH EXIT STATUS"
  echo "0 success; 1 a failed run (a write that failed during the run, out of memory, an unstable"
  echo "simulation); 2 bad usage or bad input, including an output that would replace an input or"
  echo "cannot be written (found before anything runs; nothing is written)."
  echo ".SH FILES"
  echo "Every output is written under a temporary name beside its target and renamed into place"
  echo "only when the whole command succeeded; an error, SIGINT or SIGTERM removes them and leaves an"
  echo "earlier run folder as it was."
  echo ".SH SEE ALSO"
  echo "The documents in docs/ of the source tree: architecture.md, formats.md, reliability.md."
} >"$out/verdant.1"

{
  echo "# bash completion of verdant: commands and their options (made from 'verdant --help' by"
  echo "# scripts/manpage.sh; file names everywhere else)"
  echo "_verdant() {"
  echo "  local cur=\${COMP_WORDS[COMP_CWORD]} cmd=\${COMP_WORDS[1]:-} opts=\"\""
  echo "  if [ \"\$COMP_CWORD\" -eq 1 ]; then"
  echo "    mapfile -t COMPREPLY < <(compgen -W \"${cmds[*]} help --help --version\" -- \"\$cur\")"
  echo "    return"
  echo "  fi"
  echo "  case \"\$cmd\" in"
  for c in "${cmds[@]}"; do
    o=$("$V" "$c" --help | options)
    [ "$c" = sim ] && o="$o $("$V" sim --grow --help | options)"
    echo "    $c) opts=\"$(printf '%s\n' $o | sort -u | tr '\n' ' ' | sed 's/ $//')\" ;;"
  done
  echo "    help) mapfile -t COMPREPLY < <(compgen -W \"${cmds[*]}\" -- \"\$cur\"); return ;;"
  echo "  esac"
  echo "  if [[ \$cur == -* ]]; then"
  echo "    mapfile -t COMPREPLY < <(compgen -W \"\$opts\" -- \"\$cur\")"
  echo "  else"
  echo "    mapfile -t COMPREPLY < <(compgen -f -- \"\$cur\")"
  echo "  fi"
  echo "}"
  echo "complete -o filenames -o bashdefault -F _verdant verdant"
} >"$out/verdant.bash"

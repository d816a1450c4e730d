# bash completion for every viscera binary (installed as
# share/bash-completion/completions/<binary>, one copy per name, so
# bash-completion loads it on first use). The options come from the binary's
# own --help, so they never drift from the parser (common/cli.c); a word
# after an option that names a file completes file names, and the
# sub-commands of viscera-control and viscera-asset complete as words.
_viscera() {
  local cur="${COMP_WORDS[COMP_CWORD]}" prev=""
  [ "$COMP_CWORD" -gt 0 ] && prev="${COMP_WORDS[COMP_CWORD - 1]}"
  local bin="${COMP_WORDS[0]}" name="${COMP_WORDS[0]##*/}"
  COMPREPLY=()
  case "$prev" in
    --scene | --trajectory | --out | --final-mesh | --checkpoint | --csv | --dump-mesh | --force-csv | \
      --script-input | --label | -o | -s)
      mapfile -t COMPREPLY < <(compgen -f -- "$cur")
      return 0
      ;;
    --domain | --partition | --duration | --seats | --first | --prefix | --tool | --station | --speed | --seek | \
      --wait | --rt-priority | --cpu-wake-latency | --seat-threads | --first-seat | --tile | --size | --cols | \
      --width | --height | --interval-ms | --max-frames | --command-playout | --wait-server)
      return 0 # a value the user types
      ;;
  esac
  if [[ "$cur" == -* ]]; then
    local opts
    opts="$("$bin" --help 2>/dev/null | grep -oE -- '(^|[^a-z])--[a-z][a-z0-9-]*' | grep -oE -- '--[a-z][a-z0-9-]*' |
      sort -u)"
    mapfile -t COMPREPLY < <(compgen -W "$opts -h" -- "$cur")
    return 0
  fi
  local words=""
  case "$name" in
    viscera-control) words="pause resume thresholds material reset assign guide takeover release start-task" ;;
    viscera-asset) words="info convert tet" ;;
  esac
  if [ -n "$words" ] && [ "$COMP_CWORD" -le 1 ]; then
    mapfile -t COMPREPLY < <(compgen -W "$words" -- "$cur")
    return 0
  fi
  if [ -n "$words" ]; then
    local w
    for w in "${COMP_WORDS[@]:1:COMP_CWORD-1}"; do [[ " $words " == *" $w "* ]] && break; w=""; done
    if [ -z "${w:-}" ] && [ "$name" = viscera-control ]; then
      mapfile -t COMPREPLY < <(compgen -W "$words" -- "$cur")
      return 0
    fi
  fi
  mapfile -t COMPREPLY < <(compgen -f -- "$cur")
}
complete -F _viscera viscera-server viscera-resim viscera-haptic viscera-viewer viscera-dashboard viscera-control \
  viscera-recorder viscera-recinfo viscera-replay viscera-report viscera-asset viscera-organ-gen

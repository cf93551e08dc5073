# bash completion for phiq (installed as share/bash-completion/completions/phiq). Hand-written: ctest
# bash_completion checks that it offers every command and every option `phiq COMMAND --help` lists, so that a new
# option cannot be forgotten here.

_phiq() {
  local cur prev words cword
  _init_completion -n = 2>/dev/null || {
    COMPREPLY=()
    cur="${COMP_WORDS[COMP_CWORD]}"
    prev="${COMP_WORDS[COMP_CWORD-1]}"
    words=("${COMP_WORDS[@]}")
    cword=$COMP_CWORD
  }
  local commands="run check assemble batch compare generate convert plot animate sweep-accuracy tolerance clearance modes"
  local cmd="" i
  for ((i = 1; i < cword; i++)); do
    case " $commands " in *" ${words[i]} "*) cmd="${words[i]}"; break ;; esac
  done
  if [[ -z "$cmd" ]]; then
    COMPREPLY=($(compgen -W "$commands --help --version" -- "$cur"))
    return
  fi

  local opts=""
  case "$cmd" in
    run) opts="--help --output --format --deflate --quiet --summary --threads --memory --progress --names --set
               --sensitivity --mode --drive --time --rates --forces --gravity" ;;
    check) opts="--help --json --time --set" ;;
    assemble) opts="--help --output --quiet --set" ;;
    batch) opts="--help --output --quiet --threads --summary --names --resume --sensitivity" ;;
    compare) opts="--help --rtol --atol --columns --json --junit" ;;
    generate) opts="--help --output --steps --from --to --coords --twist --outputs" ;;
    convert) opts="--help --output --drive --time --rates --forces --gravity" ;;
    plot) opts="--help --output --columns --positions --set" ;;
    animate) opts="--help --output --columns --modes --forces --set" ;;
    sweep-accuracy) opts="--help --output --json --tolerances --steps-list --predictors --newton --linear-solvers
                          --reference --repeat --quiet --verbose" ;;
    tolerance) opts="--help --output --sd --limit --covariance --samples --seed --columns --threshold --summary --plot
                     --plot-column --threads --names --quiet --set" ;;
    clearance) opts="--help --output --summary --fail-on-interference --quiet --set" ;;
    modes) opts="--help --at --along --output --threads --max-paths --quiet --set" ;;
  esac

  # values of the options that take a fixed set of words, or files
  case "$prev" in
    --progress) COMPREPLY=($(compgen -W "auto always never" -- "$cur")); return ;;
    --names) COMPREPLY=($(compgen -W "dotted identifiers" -- "$cur")); return ;;
    --format) COMPREPLY=($(compgen -W "csv hdf5" -- "$cur")); return ;;
    --coords) COMPREPLY=($(compgen -W "natural reference-point" -- "$cur")); return ;;
    --newton) COMPREPLY=($(compgen -W "modified full modified,full" -- "$cur")); return ;;
    --linear-solvers) COMPREPLY=($(compgen -W "klu umfpack dense klu,umfpack" -- "$cur")); return ;;
    --predictors) COMPREPLY=($(compgen -W "auto previous secant parabolic linear hermite quadratic cubic" -- "$cur"))
                  return ;;
    --reference) COMPREPLY=($(compgen -W "auto numerical closed-form:crank-slider closed-form:fourbar
                                          closed-form:nfourbar closed-form:chain3d" -- "$cur")); return ;;
    --summary|--junit|-o|--output|--covariance|--plot) COMPREPLY=($(compgen -f -- "$cur")); return ;;
    --threads|--memory|--steps|--from|--to|--twist|--time|--rtol|--atol|--columns|--positions|--tolerances|\
    --steps-list|--repeat|--outputs|--deflate|--sd|--limit|--samples|--seed|--threshold|--plot-column|--set|\
    --sensitivity|--at|--along|--max-paths|--mode|--drive) return ;;  # a value of the user's
  esac
  if [[ "$cur" == -* ]]; then
    COMPREPLY=($(compgen -W "$opts" -- "$cur"))
  elif [[ "$cmd" == generate && $((cword - i)) -eq 1 ]]; then
    COMPREPLY=($(compgen -W "nfourbar scissor grid chain3d" -- "$cur"))
  else
    # scenes and CSVs: files (directories to descend into)
    COMPREPLY=($(compgen -f -- "$cur"))
  fi
}
complete -o filenames -F _phiq phiq

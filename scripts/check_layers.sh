#!/usr/bin/env bash
# Fails if a layer, or its tests (tests/LAYER), includes a header of a layer it does not link,
# directly or through the layers it links (cmake/layers.txt, docs/design.md "Layers"): a layer above
# it, or one beside it. core is the bottom layer: it includes no other layer, and every layer may
# include it.
root=${1:-$(dirname "$0")/..}
order=()
declare -A links=()
while IFS= read -r line; do
  line=${line%%#*}
  [[ $line == *:* ]] || continue
  layer=${line%%:*}
  layer=${layer// /}
  order+=("$layer")
  links[$layer]=${line#*:}
done <"$root/cmake/layers.txt"
if [ ${#order[@]} -eq 0 ]; then
  echo "$root/cmake/layers.txt: no layers"
  exit 1
fi

# The layers `layer` reaches through its links, itself included.
reach() {
  local layer=$1 seen=" $1 " todo=($1)
  while [ ${#todo[@]} -gt 0 ]; do
    local next=${todo[0]}
    todo=("${todo[@]:1}")
    for dep in ${links[$next]}; do
      if [[ $seen != *" $dep "* ]]; then
        seen+="$dep "
        todo+=("$dep")
      fi
    done
  done
  echo "$seen"
}

bad=0
for layer in "${order[@]}"; do
  allowed=$(reach "$layer")
  for other in "${order[@]}"; do
    [[ $allowed == *" $other "* ]] && continue
    if hits=$(grep -rnE "#include +\"(\.\./)*$other/" "$root/$layer" "$root/tests/$layer" \
                --include='*.h' --include='*.cpp' 2>/dev/null); then
      echo "layering violation: $layer includes $other:"; echo "$hits"; bad=1
    fi
  done
done
[ $bad = 0 ] && echo "layering ok"
exit $bad

#!/bin/sh
# collect-closure.sh DEST FILE...: copy the shared-library closure of the ELF FILEs (as the loader
# resolves it, the loader included) into DEST, keeping the libraries' absolute paths. The FILEs
# themselves are not copied: the caller places them. Used by the builder stage of
# docker/Dockerfile on hosts with a registry; the orchestrator's own packer
# (orchestrator/images/) does the same in C++ for registry-free hosts.
set -eu
dest=$1
shift
for f in "$@"; do
  interp=$(readelf -l "$f" 2>/dev/null | sed -n 's/.*Requesting program interpreter: \(.*\)]/\1/p')
  [ -n "$interp" ] || interp=/lib64/ld-linux-x86-64.so.2
  "$interp" --list "$f" | awk '/=> \// { print $3 } /^[[:space:]]*\// { print $1 }' |
    while read -r lib; do
      mkdir -p "$dest$(dirname "$lib")"
      cp -L "$lib" "$dest$lib"
    done
done

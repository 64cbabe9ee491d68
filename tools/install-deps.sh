#!/usr/bin/env bash
# Install the Debian 12 packages robin_contact needs, only those that are missing.
# As root: apt-get update (once) + apt-get install. Otherwise: print the exact command.
set -eu
# the third line: ParaView (5.11: pvpython is in python3-paraview, pvbatch in paraview) and Xvfb
# for tools/paraview_view.py headless (xvfb-run -a pvpython ...; test_paraview renders with them);
# the last line is the MPI binary's (make MPI=1): OpenMPI and Debian's MPI build of MUMPS
# with the ScaLAPACK it links; the default serial build does not use them
pkgs="gfortran gcc make libsuitesparse-dev libmetis-dev libhdf5-dev libopenblas-dev liblapack-dev pkg-config
python3 python3-numpy python3-matplotlib python3-h5py python3-meshio procps
paraview python3-paraview xvfb xauth
libopenmpi-dev openmpi-bin libmumps-dev libscalapack-openmpi-dev"
missing=""
for p in $pkgs; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done
if [ -z "$missing" ]; then
  echo "install-deps: all Debian packages present"
  exit 0
fi
echo "install-deps: missing:$missing"
if [ "$(id -u)" -eq 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $missing
else
  echo "install-deps: not root; run:"
  echo "  sudo apt-get update && sudo apt-get install -y --no-install-recommends$missing"
  exit 1
fi

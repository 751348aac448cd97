#!/usr/bin/env python3
"""Counts the packets on an interface (default lo) that contain a marker, for SECONDS seconds: an
independent look at what crosses the wire (process_security_test on loopback, multihost_test.sh's
secure mode on the namespaces' bridge). Needs root (AF_PACKET).

    capture_marker.py MARKER SECONDS [INTERFACE]    prints "packets N marked M" and exits 0
"""
import socket
import sys
import time


def main():
    if len(sys.argv) not in (3, 4):
        print(__doc__, file=sys.stderr)
        return 2
    marker, seconds = sys.argv[1].encode(), float(sys.argv[2])
    interface = sys.argv[3] if len(sys.argv) == 4 else "lo"
    s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(0x0003))  # ETH_P_ALL
    s.bind((interface, 0))
    s.settimeout(0.2)
    print("capturing", flush=True)
    end = time.monotonic() + seconds
    packets = marked = 0
    while time.monotonic() < end:
        try:
            frame = s.recv(65535)
        except socket.timeout:
            continue
        packets += 1
        marked += marker in frame
    print(f"packets {packets} marked {marked}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Counts the packets on an interface (default lo) that contain a marker, for SECONDS seconds: an
independent look at what crosses the wire (process_security_test on loopback, multihost_test.sh's
secure mode on the namespaces' bridge). Needs root (AF_PACKET).

    capture_marker.py MARKER SECONDS [INTERFACE]    prints "packets N marked M" and exits 0

MARKER may be several, separated by commas (a graph's, its processes' and its hosts' names):
then M counts the packets that contain any of them, and a line "marker NAME K" follows for each.
With the environment variable CAPTURE_PCAP=FILE every packet is also written to FILE (pcap, for
tshark or Wireshark), to see what else is readable.
"""
import os
import socket
import struct
import sys
import time


def main():
    if len(sys.argv) not in (3, 4):
        print(__doc__, file=sys.stderr)
        return 2
    markers = [m.encode() for m in sys.argv[1].split(",") if m]
    seconds = float(sys.argv[2])
    interface = sys.argv[3] if len(sys.argv) == 4 else "lo"
    if not markers:
        print("capture_marker.py: no marker given", file=sys.stderr)
        return 2
    s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(0x0003))  # ETH_P_ALL
    s.bind((interface, 0))
    s.settimeout(0.2)
    pcap = None
    if os.environ.get("CAPTURE_PCAP"):
        pcap = open(os.environ["CAPTURE_PCAP"], "wb")
        pcap.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1))  # Ethernet link type
    print("capturing", flush=True)
    end = time.monotonic() + seconds
    packets = marked = 0
    per_marker = {m: 0 for m in markers}
    while time.monotonic() < end:
        try:
            frame = s.recv(65535)
        except socket.timeout:
            continue
        packets += 1
        found = [m for m in markers if m in frame]
        marked += bool(found)
        for m in found:
            per_marker[m] += 1
        if pcap:
            now = time.time()
            pcap.write(struct.pack("<IIII", int(now), int((now % 1) * 1e6), len(frame), len(frame)) + frame)
    if pcap:
        pcap.close()
    print(f"packets {packets} marked {marked}", flush=True)
    if len(markers) > 1:
        for m in markers:
            print(f"marker {m.decode()} {per_marker[m]}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

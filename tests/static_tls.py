#!/usr/bin/env python3
"""Every thread's static TLS comes out of its stack, and civetweb's worker threads have 100 KB
stacks (Debian's libcivetweb 1.15 is built with USE_STACK_SIZE 102400, no option changes it), of
which OpenSSL 3's TLS handshake and SSL_write leave a few KB (measured: 4.6 KB of thread_local data
in the dyad command crashed HTTPS pages and the WebSocket handshake; a 5 KB std::mt19937 did,
commit 808144f). So the dyad command and every library and plugin it loads keep their
thread-local data small. Usage: static_tls.py BUILD_DIR [LIMIT_BYTES]"""
import glob
import subprocess
import sys

build = sys.argv[1]
limit = int(sys.argv[2]) if len(sys.argv) > 2 else 1024
files = [f"{build}/bin/dyad"] + sorted(glob.glob(f"{build}/lib/*.so")) + sorted(glob.glob(f"{build}/plugins/*.so"))
total, problems = 0, []
for f in files:
    out = subprocess.run(["readelf", "-lW", f], capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        fields = line.split()
        if fields and fields[0] == "TLS":
            size = int(fields[5], 16)  # MemSiz
            total += size
            if size > limit:
                problems.append(f"{f}: {size} bytes of thread-local data (at most {limit}): "
                                "a large thread_local (an RNG engine, a buffer) belongs in an object, not in every thread")
if total > 2 * limit:
    problems.append(f"{total} bytes of thread-local data in all (at most {2 * limit})")
for p in problems:
    print("FAIL:", p)
print(f"static TLS: {total} bytes over {len(files)} files (limit {limit} each)")
sys.exit(1 if problems else 0)

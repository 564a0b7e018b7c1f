#!/usr/bin/env python3
"""A stand-in for the tev viewer when measuring what `render --display` costs: it accepts
connections on a port, reads whole packets (a little-endian u32 length that counts itself, then
the type byte) and throws them away, printing per connection how many of each type came and
how many bytes. Nothing is drawn, so the measure is the renderer's side alone.
  usage: scripts/tev-sink.py [PORT]    (14158 by default; Ctrl-C ends it)
"""

import socket
import struct
import sys
import threading
from collections import Counter


def read_exactly(conn, n):
    data = bytearray()
    while len(data) < n:
        chunk = conn.recv(min(n - len(data), 1 << 20))
        if not chunk:
            return None
        data += chunk
    return bytes(data)


def serve(conn, peer):
    kinds, total = Counter(), 0
    with conn:
        while (head := read_exactly(conn, 4)) is not None:
            (length,) = struct.unpack("<I", head)
            body = read_exactly(conn, length - 4)
            if body is None:
                print(f"{peer}: the connection ended inside a packet", file=sys.stderr)
                break
            kinds[body[0]] += 1
            total += length
    print(f"{peer}: {dict(sorted(kinds.items()))} packets by type, {total} bytes", flush=True)


def main():
    port = int(sys.argv[1]) if len(sys.argv) > 1 else 14158
    with socket.create_server(("127.0.0.1", port)) as server:
        print(f"listening on 127.0.0.1:{port}", flush=True)
        while True:
            conn, (host, peer_port) = server.accept()
            threading.Thread(target=serve, args=(conn, f"{host}:{peer_port}"), daemon=True).start()


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:
        pass

"""A Modbus TCP proxy that can refuse writes: it passes every request of its client to a device
(hsa-simdev) and the device's answer back, and while `refuse_writes` is set it answers every write
(functions 5, 6, 15, 16) itself with exception 3 (illegal data value) instead, as a coupler or
drive does that refuses an output value, and passes reads on as before. Written from the Modbus
Application Protocol specification (MBAP header: transaction id, protocol id 0, length, unit id),
independent of hsa's own Modbus code. One upstream connection per client connection, so the device
sees the proxy's connection as the master's.
"""
import socket
import struct
import threading

WRITE_FUNCTIONS = {5, 6, 15, 16}
ILLEGAL_DATA_VALUE = 3


def _read_exactly(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("closed")
        data += chunk
    return data


def _read_frame(sock):
    header = _read_exactly(sock, 7)
    _, _, length, _ = struct.unpack(">HHHB", header)
    if not 2 <= length <= 254:
        raise ConnectionError(f"bad MBAP length {length}")
    return header, _read_exactly(sock, length - 1)


class RefusingProxy:
    def __init__(self, listen_port, device_port):
        self.device_port = device_port
        self.refuse_writes = threading.Event()
        self.refused = 0  # writes answered with exception 3
        self._server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._server.bind(("127.0.0.1", listen_port))
        self._server.listen(4)
        self._server.settimeout(0.2)
        self._stop = threading.Event()
        self._threads = [threading.Thread(target=self._accept, daemon=True)]
        self._threads[0].start()

    def close(self):
        self._stop.set()
        for t in self._threads:
            t.join(timeout=2)
        self._server.close()

    def _accept(self):
        while not self._stop.is_set():
            try:
                client, _ = self._server.accept()
            except socket.timeout:
                continue
            t = threading.Thread(target=self._serve, args=(client,), daemon=True)
            self._threads.append(t)
            t.start()

    def _serve(self, client):
        client.settimeout(0.2)
        upstream = socket.create_connection(("127.0.0.1", self.device_port), timeout=2)
        try:
            while not self._stop.is_set():
                try:
                    header, pdu = _read_frame(client)
                except socket.timeout:
                    continue
                transaction, _, _, unit = struct.unpack(">HHHB", header)
                if self.refuse_writes.is_set() and pdu[0] in WRITE_FUNCTIONS:
                    self.refused += 1
                    client.sendall(struct.pack(">HHHBBB", transaction, 0, 3, unit, pdu[0] | 0x80,
                                               ILLEGAL_DATA_VALUE))
                    continue
                upstream.sendall(header + pdu)
                answer_header, answer = _read_frame(upstream)
                client.sendall(answer_header + answer)
        except (ConnectionError, OSError):
            pass
        finally:
            client.close()
            upstream.close()

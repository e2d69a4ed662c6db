"""Devices that answer SSDP but whose description never comes right: one hangs, one trickles, one is huge."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from typing import Literal

from plugnproduce.protocols.upnp import SERVICE_TYPE, SsdpNetwork
from tests.lines import WAIT

Kind = Literal["hang", "slowloris", "huge"]

HUGE = 100 * 1024 * 1024
"""What the huge device says its description is: 100 MB."""


class HostileDevice:
    """Answers every M-SEARCH on ``network`` as ``udn`` and announces itself once; its description URL hangs
    (``hang``: reads the request, answers nothing), trickles a byte at a time (``slowloris``) or is 100 MB
    (``huge``). Threads and plain sockets, so it works beside any event loop and beside subprocesses."""

    def __init__(self, network: SsdpNetwork, udn: str, kind: Kind) -> None:
        self.network, self.udn, self.kind = network, udn, kind
        self.http = socket.create_server(("127.0.0.1", 0))
        self.http.settimeout(0.2)
        self.location = f"http://127.0.0.1:{self.http.getsockname()[1]}/description.xml"
        self.ssdp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.ssdp.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.ssdp.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        self.ssdp.bind(("", network.port))
        self.ssdp.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                             socket.inet_aton(network.group) + socket.inet_aton(network.interface))
        self.ssdp.settimeout(0.2)
        self.requests = 0
        """HTTP requests the device received."""
        self._stop = threading.Event()
        self._threads = [threading.Thread(target=self._answer_searches, daemon=True),
                         threading.Thread(target=self._serve_http, daemon=True)]

    def __enter__(self) -> HostileDevice:
        for thread in self._threads:
            thread.start()
        self.announce()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(10)
        self.ssdp.close()
        self.http.close()

    def announce(self) -> None:
        """One SSDP ``alive``."""
        message = (f"NOTIFY * HTTP/1.1\r\nHOST: {self.network.group}:{self.network.port}\r\n"
                   f"CACHE-CONTROL: max-age=1800\r\nLOCATION: {self.location}\r\nNT: upnp:rootdevice\r\n"
                   f"NTS: ssdp:alive\r\nSERVER: hostile/1 UPnP/1.0 x/1\r\nUSN: {self.udn}::upnp:rootdevice\r\n\r\n")
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(self.network.interface))
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            sock.sendto(message.encode(), (self.network.group, self.network.port))

    def _answer_searches(self) -> None:
        while not self._stop.is_set():
            try:
                data, addr = self.ssdp.recvfrom(4096)
            except TimeoutError:
                continue
            if data.startswith(b"M-SEARCH"):
                self.ssdp.sendto((f"HTTP/1.1 200 OK\r\nCACHE-CONTROL: max-age=1800\r\nEXT:\r\n"
                                  f"LOCATION: {self.location}\r\nSERVER: hostile/1 UPnP/1.0 x/1\r\n"
                                  f"ST: {SERVICE_TYPE}\r\nUSN: {self.udn}::{SERVICE_TYPE}\r\n\r\n").encode(), addr)

    def _serve_http(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self.http.accept()
            except TimeoutError:
                continue
            self.requests += 1
            threading.Thread(target=self._answer, args=(conn,), daemon=True).start()

    def _answer(self, conn: socket.socket) -> None:
        with conn, contextlib.suppress(OSError):
            conn.settimeout(WAIT)  # a controller busy elsewhere for a second must find the request read, the body whole
            conn.recv(4096)
            if self.kind == "huge":
                conn.sendall(f"HTTP/1.1 200 OK\r\nContent-Type: text/xml\r\nContent-Length: {HUGE}\r\n\r\n".encode())
                chunk, sent = b"<" * 65536, 0
                while sent < HUGE and not self._stop.is_set():
                    conn.sendall(chunk)
                    sent += len(chunk)
                return
            if self.kind == "slowloris":
                conn.sendall(b"HTTP/1.1 200 OK\r\nContent-Type: text/xml\r\n")
            while not self._stop.is_set():  # hang: say nothing; slow loris: one byte of a header at a time
                time.sleep(0.2)
                if self.kind == "slowloris":
                    conn.sendall(b"X")

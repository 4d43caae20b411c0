"""A minimal LSP client over stdio, as an editor drives a server (tests and bench)."""
import json
import os
import queue
import subprocess
import threading
import time


class LspClient:
    def __init__(self, command):
        self.proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE)
        self.next_id = 0
        self.responses = {}
        self.notifications = queue.Queue()
        self.cond = threading.Condition()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        out = self.proc.stdout
        while True:
            headers = {}
            while True:
                line = out.readline()
                if not line:
                    with self.cond:
                        self.cond.notify_all()
                    return
                line = line.strip()
                if not line:
                    break
                k, _, v = line.decode().partition(":")
                headers[k.strip().lower()] = v.strip()
            body = out.read(int(headers["content-length"]))
            msg = json.loads(body)
            if "id" in msg and "method" not in msg:
                with self.cond:
                    self.responses[json.dumps(msg["id"])] = msg
                    self.cond.notify_all()
            else:
                self.notifications.put((time.perf_counter(), msg))

    def send_raw(self, body: bytes, header=None):
        header = header if header is not None else b"Content-Length: %d\r\n\r\n" % len(body)
        self.proc.stdin.write(header + body)
        self.proc.stdin.flush()

    def send(self, msg):
        self.send_raw(json.dumps(msg).encode())

    def request_async(self, method, params=None, id=None):
        if id is None:
            self.next_id += 1
            id = self.next_id
        msg = {"jsonrpc": "2.0", "id": id, "method": method}
        if params is not None:
            msg["params"] = params
        self.send(msg)
        return id

    def wait(self, id, timeout=30):
        key = json.dumps(id)
        with self.cond:
            ok = self.cond.wait_for(lambda: key in self.responses or self.proc.poll() is not None, timeout)
            if key not in self.responses:
                raise TimeoutError(f"no response to {id} (server exit {self.proc.poll()})")
            return self.responses.pop(key)

    def request(self, method, params=None, timeout=30):
        return self.wait(self.request_async(method, params), timeout)

    def notify(self, method, params=None):
        msg = {"jsonrpc": "2.0", "method": method}
        if params is not None:
            msg["params"] = params
        self.send(msg)

    def wait_notification(self, method, predicate=lambda m: True, timeout=30):
        deadline = time.time() + timeout
        while True:
            left = deadline - time.time()
            if left <= 0:
                raise TimeoutError(f"no {method} notification")
            t, msg = self.notifications.get(timeout=left)
            if msg.get("method") == method and predicate(msg):
                return t, msg

    def initialize(self):
        r = self.request("initialize", {"processId": os.getpid(), "rootUri": None, "capabilities": {}})
        self.notify("initialized", {})
        return r

    def close(self, timeout=30):
        try:
            self.proc.stdin.close()
        except BrokenPipeError:
            pass
        return self.proc.wait(timeout)

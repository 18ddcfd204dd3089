// The live websocket of one run (/api/runs/{id}/live; frames and commands are documented in
// server/api/routes/live.py). Commands are answered by an ack or an error with the same id;
// send() returns a promise settled by that answer. A connection lost before the run's "end"
// frame is reopened a few times, with the subscriptions sent again.

const NOT_FOUND_CODE = 4404; // the server's close code: no such run, or not yours
const RECONNECTS = 5;
const ANSWER_TIMEOUT_MS = 10000;

export class LiveRun {
  /**
   * @param {string} runId
   * @param {{onFrame: (frame: object) => void, onStatus?: (text: string) => void}} handlers
   */
  constructor(runId, { onFrame, onStatus = () => {} }) {
    this.runId = runId;
    this.onFrame = onFrame;
    this.onStatus = onStatus;
    this.socket = null;
    this.nextId = 1;
    this.pending = new Map(); // id -> {resolve, reject, timer}
    this.subscriptions = new Map(); // topic -> max_rate_hz
    this.ended = false;
    this.closed = false;
    this.failures = 0;
    this.connect();
  }

  connect() {
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    const socket = new WebSocket(`${scheme}//${location.host}/api/runs/${this.runId}/live`);
    this.socket = socket;
    socket.addEventListener("open", () => {
      this.failures = 0;
      this.onStatus("");
      // A run that ends at once closes the socket before it answers: nothing to report then
      // (a reconnect subscribes again).
      for (const [topic, rate] of this.subscriptions) {
        this.command("subscribe", { topic, max_rate_hz: rate }).catch(() => {});
      }
    });
    socket.addEventListener("message", (event) => this.receive(event.data));
    socket.addEventListener("close", (event) => this.lost(event));
  }

  receive(text) {
    let frame;
    try {
      frame = JSON.parse(text);
    } catch {
      return;
    }
    if (frame.type === "ack" || frame.type === "error") {
      const waiting = this.pending.get(frame.id);
      if (waiting) {
        this.pending.delete(frame.id);
        clearTimeout(waiting.timer);
        if (frame.type === "ack") waiting.resolve();
        else waiting.reject(new Error(frame.detail));
        return;
      }
    }
    if (frame.type === "end") this.ended = true;
    this.onFrame(frame);
  }

  lost(event) {
    for (const waiting of this.pending.values()) {
      clearTimeout(waiting.timer);
      waiting.reject(new Error("the connection to the run closed before it answered"));
    }
    this.pending.clear();
    if (this.closed || this.ended) return;
    if (event.code === NOT_FOUND_CODE) {
      this.onStatus(`live view refused: ${event.reason || "no such run"}`);
      this.onFrame({ type: "gone", reason: event.reason });
      return;
    }
    this.failures += 1;
    if (this.failures > RECONNECTS) {
      this.onStatus("the live connection is lost; reload the page to see the run");
      this.onFrame({ type: "gone", reason: "connection lost" });
      return;
    }
    this.onStatus(`live connection lost; reconnecting (${this.failures}/${RECONNECTS})`);
    setTimeout(() => !this.closed && this.connect(), 500 * this.failures);
  }

  /** Send {op, ...fields}; resolves on ack, rejects with the server's sentence on error. */
  command(op, fields = {}) {
    if (!this.socket || this.socket.readyState !== WebSocket.OPEN) {
      return Promise.reject(new Error("not connected to the run"));
    }
    const id = this.nextId++;
    this.socket.send(JSON.stringify({ id, op, ...fields }));
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => {
        this.pending.delete(id);
        reject(new Error(`the server did not answer '${op}'`));
      }, ANSWER_TIMEOUT_MS);
      this.pending.set(id, { resolve, reject, timer });
    });
  }

  /** Follow a topic at `rateHz` at most (again with another rate changes it); 0 stops. */
  follow(topic, rateHz) {
    const open = this.socket && this.socket.readyState === WebSocket.OPEN;
    if (rateHz > 0) {
      if (this.subscriptions.get(topic) === rateHz) return;
      this.subscriptions.set(topic, rateHz);
      if (open) this.command("subscribe", { topic, max_rate_hz: rateHz }).catch(() => {});
    } else if (this.subscriptions.delete(topic) && open) {
      this.command("unsubscribe", { topic }).catch(() => {});
    }
  }

  close() {
    this.closed = true;
    if (this.socket) this.socket.close();
  }
}

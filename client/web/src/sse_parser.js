// Incremental Server-Sent Events parser (WHATWG "event stream interpretation"), fed with text chunks as
// they arrive from fetch()'s ReadableStream. The page uses fetch rather than EventSource because
// EventSource cannot send the Authorization header.

/** One dispatched event. */
export class SseEvent {
  /** @param {string} type  the `event:` field, "message" when absent @param {string} data  `data:` lines joined by '\n' */
  constructor(type, data) {
    this.type = type;
    this.data = data;
  }
}

export class SseParser {
  constructor() {
    this.m_buffer = '';
    this.m_type = '';
    this.m_data = [];
  }

  /**
   * Adds a chunk of the stream.
   * @param {string} chunk  decoded text (may end mid-line)
   * @returns {SseEvent[]}  the events completed by this chunk, in order
   */
  feed(chunk) {
    this.m_buffer += chunk;
    const events = [];
    // A line ends at \r\n, \n or \r; a trailing lone \r might be the first half of \r\n, so wait for more.
    let match;
    const line_end = /\r\n|\n|\r(?!$)/g;
    let consumed = 0;
    while ((match = line_end.exec(this.m_buffer)) !== null) {
      const line = this.m_buffer.slice(consumed, match.index);
      consumed = match.index + match[0].length;
      const event = this.take_line(line);
      if (event !== null) events.push(event);
    }
    this.m_buffer = this.m_buffer.slice(consumed);
    return events;
  }

  /** One complete line: a field, a comment, or the blank line that dispatches. */
  take_line(line) {
    if (line.length === 0) {
      if (this.m_data.length === 0) {
        this.m_type = '';
        return null;
      }
      const event = new SseEvent(this.m_type || 'message', this.m_data.join('\n'));
      this.m_type = '';
      this.m_data = [];
      return event;
    }
    if (line[0] === ':') return null;  // comment, e.g. ": keepalive"
    const colon = line.indexOf(':');
    const field = colon < 0 ? line : line.slice(0, colon);
    let value = colon < 0 ? '' : line.slice(colon + 1);
    if (value[0] === ' ') value = value.slice(1);
    if (field === 'event') this.m_type = value;
    else if (field === 'data') this.m_data.push(value);
    // `id` and `retry` are not used by this API.
    return null;
  }
}

// The HTTP/JSON API of balloon-server (/api/v1, see notes/web-api.md): protobuf's JSON mapping with
// proto field names, enums as strings, int64 as strings, bytes as base64. Every call sends the bearer
// token when one is set; errors come back as ApiError with the service's code, message and bad fields.
import { SseParser } from './sse_parser.js';

/** An API call that failed: HTTP status, the service's status code name, its message and the bad fields. */
export class ApiError extends Error {
  /**
   * @param {number} status  HTTP status (0 when the server could not be reached)
   * @param {string} code  status code name, e.g. "INVALID_ARGUMENT"
   * @param {string} message  the service's message, in plain words
   * @param {{field: string, description: string}[]} [fields]  the request fields at fault, by path
   *   ("design.thickness_mm"); empty when the service named none
   */
  constructor(status, code, message, fields = []) {
    super(message);
    this.status = status;
    this.code = code;
    this.fields = fields;
  }
}

/** ArrayBuffer -> base64 (the JSON mapping of `bytes`), in chunks so large meshes do not overflow the stack. */
export function base64_from_bytes(bytes) {
  const view = new Uint8Array(bytes);
  let binary = '';
  const CHUNK = 0x8000;
  for (let i = 0; i < view.length; i += CHUNK) binary += String.fromCharCode(...view.subarray(i, i + CHUNK));
  return btoa(binary);
}

/** base64 -> Uint8Array. */
export function bytes_from_base64(text) {
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

/** A response that is not 2xx -> ApiError, reading the API's `{"error":{code,message,fields}}` body when there is one. */
async function error_from_response(response) {
  const text = await response.text().catch(() => '');
  try {
    const body = JSON.parse(text);
    if (body && body.error && typeof body.error.message === 'string') {
      const fields = Array.isArray(body.error.fields) ? body.error.fields.filter((f) => f && typeof f.field === 'string') : [];
      return new ApiError(response.status, body.error.code || 'UNKNOWN', body.error.message, fields);
    }
  } catch {
    // not JSON: fall through to the plain text
  }
  const message = text.trim() || response.statusText || `HTTP ${response.status}`;
  return new ApiError(response.status, response.status === 404 ? 'NOT_FOUND' : 'UNKNOWN', message);
}

export class ApiClient {
  /**
   * @param {() => string} token_source  returns the bearer token to send, '' for none
   * @param {(message: string) => void} [on_unauthenticated]  told whenever the server wants a (valid) token
   * @param {string} [base]  URL prefix of the server ('' = the page's own origin)
   */
  constructor(token_source, on_unauthenticated = () => {}, base = '') {
    this.m_token_source = token_source;
    this.m_on_unauthenticated = on_unauthenticated;
    this.m_base = base;
  }

  /** The ApiError for a failed response, telling the token field when the token was the problem. */
  async failure(response) {
    const error = await error_from_response(response);
    if (error.code === 'UNAUTHENTICATED') this.m_on_unauthenticated(error.message);
    return error;
  }

  headers(extra = {}) {
    const headers = { ...extra };
    const token = this.m_token_source();
    if (token) headers['Authorization'] = `Bearer ${token}`;
    return headers;
  }

  /** fetch() that turns "server unreachable" into an ApiError with a plain message. */
  async fetch_or_throw(path, options) {
    try {
      return await fetch(this.m_base + path, options);
    } catch (error) {
      if (error && error.name === 'AbortError') throw error;
      throw new ApiError(0, 'UNAVAILABLE', `the server cannot be reached (${error.message})`);
    }
  }

  /**
   * One JSON call.
   * @param {string} method  GET, POST, PUT, DELETE
   * @param {string} path  below the server root, e.g. "/api/v1/jobs"
   * @param {object} [body]  request message (JSON mapping)
   * @returns {Promise<object>} the response message
   */
  async request(method, path, body) {
    const options = { method, headers: this.headers({ Accept: 'application/json' }) };
    if (body !== undefined) {
      options.headers['Content-Type'] = 'application/json';
      options.body = JSON.stringify(body);
    }
    const response = await this.fetch_or_throw(path, options);
    if (!response.ok) throw await this.failure(response);
    const text = await response.text();
    return text ? JSON.parse(text) : {};
  }

  /** GET /health -> {status}. */
  health() {
    return this.request('GET', '/api/v1/health');
  }
  /** Presets first, then the caller's own materials: [Material]. */
  async list_materials() {
    return (await this.request('GET', '/api/v1/materials')).materials ?? [];
  }
  /** Submits a JobSpec; returns the stored Job (QUEUED). */
  async submit_job(spec) {
    return (await this.request('POST', '/api/v1/jobs', { spec })).job;
  }
  /** The caller's jobs, newest first: {jobs, next_page_token}. */
  list_jobs(page_size = 50) {
    return this.request('GET', `/api/v1/jobs?page_size=${page_size}`);
  }
  /** One Job. */
  get_job(job_id) {
    return this.request('GET', `/api/v1/jobs/${encodeURIComponent(job_id)}`);
  }
  /** Cancels a queued or running job; returns the Job. */
  cancel_job(job_id) {
    return this.request('POST', `/api/v1/jobs/${encodeURIComponent(job_id)}/cancel`, {});
  }
  /** JobResult of a COMPLETED job, meshes as OBJ (base64 in rest_mesh.data / inflated_mesh.data). */
  get_result(job_id) {
    return this.request('GET', `/api/v1/jobs/${encodeURIComponent(job_id)}/result?format=MESH_FORMAT_OBJ`);
  }

  /**
   * A result file (rest.obj, inflated.obj, mold.stl, report.json, convergence.csv, fit.svg) as a Blob, with the token.
   * @returns {Promise<Blob>}
   */
  async fetch_file(job_id, file_name) {
    const path = `/api/v1/jobs/${encodeURIComponent(job_id)}/files/${encodeURIComponent(file_name)}`;
    const response = await this.fetch_or_throw(path, { headers: this.headers() });
    if (!response.ok) throw await this.failure(response);
    return await response.blob();
  }

  /**
   * A result's SVG plot (fit.svg, curve.svg) as an object URL for an <img>, re-typed image/svg+xml so that
   * it renders whatever Content-Type the server sent. The caller revokes it (URL.revokeObjectURL).
   * @returns {Promise<string>}
   */
  async fetch_svg_url(job_id, file_name) {
    const text = await (await this.fetch_file(job_id, file_name)).text();
    return URL.createObjectURL(new Blob([text], { type: 'image/svg+xml' }));
  }

  /**
   * Streams a job's events until the job finishes (Server-Sent Events read with fetch so the token can
   * be sent).
   * @param {string} job_id
   * @param {(event: object) => void} on_event  called with each JobEvent (JSON mapping)
   * @param {AbortSignal} [signal]  stops watching (the promise then rejects with an AbortError)
   * @returns {Promise<{code: string, message: string}>}  how the stream ended ("OK" when the job finished)
   */
  async watch_job(job_id, on_event, signal) {
    const path = `/api/v1/jobs/${encodeURIComponent(job_id)}/events`;
    const response = await this.fetch_or_throw(path, {
      headers: this.headers({ Accept: 'text/event-stream' }),
      signal,
    });
    if (!response.ok) throw await this.failure(response);
    const reader = response.body.getReader();
    const decoder = new TextDecoder();
    const parser = new SseParser();
    for (;;) {
      const { value, done } = await reader.read();
      if (done) break;
      for (const event of parser.feed(decoder.decode(value, { stream: true }))) {
        if (event.type === 'job') on_event(JSON.parse(event.data));
        else if (event.type === 'end') {
          reader.cancel().catch(() => {});
          return JSON.parse(event.data);
        }
      }
    }
    return { code: 'UNAVAILABLE', message: 'the event stream closed before the job finished' };
  }
}

// The optional API token, kept in the browser's localStorage so a reload keeps it.

const STORAGE_KEY = 'balloon.api_token';

export class TokenStore {
  /** @param {Storage} storage  usually window.localStorage */
  constructor(storage) {
    this.m_storage = storage;
    try {
      this.m_token = storage.getItem(STORAGE_KEY) ?? '';
    } catch {
      this.m_token = '';  // storage blocked (e.g. privacy settings): keep the token for this page only
    }
  }

  /** The bearer token to send; '' sends none. */
  get token() {
    return this.m_token;
  }

  /** Stores a new token ('' forgets it). */
  set token(value) {
    this.m_token = value.trim();
    try {
      if (this.m_token) this.m_storage.setItem(STORAGE_KEY, this.m_token);
      else this.m_storage.removeItem(STORAGE_KEY);
    } catch {
      // not persisted; still used for this page
    }
  }
}

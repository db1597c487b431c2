// The target file of each design job this browser submitted, kept in IndexedDB: the server stores the
// rest and inflated meshes but does not hand the target back, and reopening a job needs it for the
// target overlay and the error colouring.

const DATABASE = 'balloon-web';
const STORE = 'targets';
const KEEP_LATEST = 30;  // older targets are dropped so the browser's storage stays small

function open_database() {
  return new Promise((resolve, reject) => {
    const request = indexedDB.open(DATABASE, 1);
    request.onupgradeneeded = () => request.result.createObjectStore(STORE);
    request.onsuccess = () => resolve(request.result);
    request.onerror = () => reject(request.error);
  });
}

function transaction_done(transaction) {
  return new Promise((resolve, reject) => {
    transaction.oncomplete = () => resolve();
    transaction.onerror = () => reject(transaction.error);
    transaction.onabort = () => reject(transaction.error);
  });
}

/**
 * Remembers a job's target. Failures (no IndexedDB, quota) are ignored: only reopening loses the overlay.
 * @param {string} job_id
 * @param {{name: string, bytes: ArrayBuffer, size_mm: number}} target  file name, bytes, asked size (mm)
 */
export async function remember_target(job_id, target) {
  try {
    const database = await open_database();
    const writing = database.transaction(STORE, 'readwrite');
    writing.objectStore(STORE).put({ ...target, saved_ms: Date.now() }, job_id);
    await transaction_done(writing);

    // Drop all but the newest KEEP_LATEST targets.
    const pruning = database.transaction(STORE, 'readwrite');
    const saved = [];
    pruning.objectStore(STORE).openCursor().onsuccess = (event) => {
      const cursor = event.target.result;
      if (!cursor) {
        saved.sort((a, b) => b.saved_ms - a.saved_ms);
        for (const entry of saved.slice(KEEP_LATEST)) pruning.objectStore(STORE).delete(entry.key);
        return;
      }
      saved.push({ key: cursor.key, saved_ms: cursor.value?.saved_ms ?? 0 });
      cursor.continue();
    };
    await transaction_done(pruning);
    database.close();
  } catch {
    // not remembered
  }
}

/**
 * A job's target, or null when this browser did not submit it (or forgot it).
 * @param {string} job_id
 * @returns {Promise<{name: string, bytes: ArrayBuffer, size_mm: number}|null>}
 */
export async function recall_target(job_id) {
  try {
    const database = await open_database();
    const transaction = database.transaction(STORE, 'readonly');
    const request = transaction.objectStore(STORE).get(job_id);
    const value = await new Promise((resolve, reject) => {
      request.onsuccess = () => resolve(request.result ?? null);
      request.onerror = () => reject(request.error);
    });
    database.close();
    return value;
  } catch {
    return null;
  }
}

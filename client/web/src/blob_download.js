// Saves a Blob as a file through a temporary <a download> link (the browser's normal download).

/**
 * @param {Blob} blob  the file's content
 * @param {string} file_name  the name the browser saves it under
 */
export function save_blob(blob, file_name) {
  const url = URL.createObjectURL(blob);
  const link = document.createElement('a');
  link.href = url;
  link.download = file_name;
  link.hidden = true;
  document.body.appendChild(link);
  link.click();
  link.remove();
  // Revoke later: some browsers read the URL after click() returns.
  setTimeout(() => URL.revokeObjectURL(url), 30000);
}

// geoshade serve: the page's view in its address, #view=<base64url of {"file", "as", "state"}>
// (geoshade.web.address): the file as the server lists it, its part and the View's state (every
// option not at its default and the camera), written after every lossless frame; a page opened
// with it sends it back with its "open" (the server checks it as any change).
"use strict";
const ADDRESS = "view";

function b64url(text) {
  const bytes = new TextEncoder().encode(text);
  let s = "";
  for (let i = 0; i < bytes.length; i += 8192) s += String.fromCharCode(...bytes.subarray(i, i + 8192));
  return btoa(s).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
}

function unb64url(text) {
  const s = atob(text.replace(/-/g, "+").replace(/_/g, "/"));
  return new TextDecoder("utf-8", { fatal: true }).decode(Uint8Array.from(s, (c) => c.charCodeAt(0)));
}

// {view} from the address, {error: one line} where it cannot be read, null where it has none
function readAddress() {
  const m = new RegExp("(?:^#|&)" + ADDRESS + "=([^&]*)").exec(location.hash);
  if (!m) return null;
  try {
    const v = JSON.parse(unb64url(m[1]));
    const ok = v && typeof v === "object" && !Array.isArray(v) && typeof v.file === "string" &&
      (v.state === undefined || (v.state && typeof v.state === "object" && !Array.isArray(v.state)));
    if (ok) return { view: v };
  } catch (e) { /* said below */ }
  return { error: "the view in the address: not readable (expected #view= and base64url JSON " +
                  "naming a file); the file is shown as it opens" };
}

function writeAddress(view) {
  const hash = "#" + ADDRESS + "=" + b64url(JSON.stringify(view));
  if (location.hash !== hash) history.replaceState(null, "", location.pathname + location.search + hash);
  state.address = hash;
}

// The run's summary JSON as a two-column table (nested keys dotted).
export function showSummary(summary) {
  const section = document.getElementById("summary");
  const table = document.getElementById("summary-table");
  table.textContent = "";
  if (!summary || typeof summary !== "object") {
    section.hidden = true;
    return;
  }
  const rows = [];
  (function walk(obj, prefix) {
    for (const [k, v] of Object.entries(obj)) {
      const key = prefix ? prefix + "." + k : k;
      if (v && typeof v === "object" && !Array.isArray(v)) walk(v, key);
      else rows.push([key, Array.isArray(v) ? v.join(", ") : String(v)]);
    }
  })(summary, "");
  for (const [k, v] of rows) {
    const tr = table.insertRow();
    tr.insertCell().textContent = k;
    tr.insertCell().textContent = v;
  }
  section.hidden = rows.length === 0;
}

// Sort the leaderboard tables by the column named in location.hash (#sort=key or #sort=-key).
(function () {
  "use strict";
  var tables = Array.prototype.slice.call(document.querySelectorAll("table.sortable"));

  function cellValue(row, col, type) {
    var v = row.cells[col].getAttribute("data-v");
    if (type === "num") { return v === "" ? null : Number(v); }
    return v === "" ? null : v;
  }

  function compare(x, y, type) {
    if (type === "num") { return x < y ? -1 : (x > y ? 1 : 0); }
    return x.localeCompare(y);
  }

  function sortTable(table, key, descending) {
    var heads = table.tHead.rows[0].cells, col = -1, type = "str", rankCol = -1, i;
    for (i = 0; i < heads.length; i++) {
      if (heads[i].getAttribute("data-key") === key) { col = i; type = heads[i].getAttribute("data-type"); }
      if (heads[i].getAttribute("data-key") === "rank") { rankCol = i; }
    }
    if (col < 0) { return false; }
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = cellValue(a, col, type), y = cellValue(b, col, type), c;
      if (x === null || y === null) {
        c = (x === null) - (y === null);  // empty cells last in either direction
      } else {
        c = compare(x, y, type);
        if (descending) { c = -c; }
      }
      return c !== 0 ? c : cellValue(a, rankCol, "num") - cellValue(b, rankCol, "num");
    });
    rows.forEach(function (row) { body.appendChild(row); });
    for (i = 0; i < heads.length; i++) {
      heads[i].setAttribute("aria-sort", i === col ? (descending ? "descending" : "ascending") : "none");
    }
    return true;
  }

  function sortFromHash() {
    var m = /(?:^#|&)sort=(-?)([A-Za-z0-9_]+)/.exec(location.hash);
    var key = m ? m[2] : "rank", descending = m ? m[1] === "-" : false;
    tables.forEach(function (table) { sortTable(table, key, descending); });
    document.documentElement.setAttribute("data-sorted", (descending ? "-" : "") + key);
  }

  tables.forEach(function (table) {
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th) {
      th.querySelector("button").addEventListener("click", function () {
        var descending = th.getAttribute("aria-sort") === "ascending";
        location.hash = "sort=" + (descending ? "-" : "") + th.getAttribute("data-key");
      });
    });
  });
  window.addEventListener("hashchange", sortFromHash);
  sortFromHash();
}());

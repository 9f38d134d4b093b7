// The Accept buttons of `harness review` (served pages only; the page written by `check` has
// none). Each failing row, each scene and the whole run get one; a click posts to /accept with
// the run's token and the reason typed above them (recorded beside each golden written, as
// `harness bless --reason` records it), and the rows of what was accepted are marked.
(function () {
  const review = window.HARNESS_REVIEW;
  if (!review) return;
  const style = document.createElement('style');
  style.textContent =
    'button.accept{margin-right:.5em} tr.accepted td{background:#e3f4e3}' +
    ' .accept-bar{margin:.5em 0} .accept-bar button{margin-right:.4em}' +
    ' .accept-bar input.accept-reason{width:36em;margin:0 .4em .4em 0}' +
    ' ul.accept-notes{background:#f4f4e3;padding:.4em 1.6em}';
  document.head.appendChild(style);

  // A speed row's pass is a plan pass; the server names an accepted timing `speed <pass>`. An
  // image golden serves every backend's row of its pass; a timing golden is one backend's.
  const key = (row) => (row.dataset.speed ? 'speed ' : '') + row.dataset.pass;

  function mark(accepted) {
    for (const [scene, pass, backend] of accepted) {
      const rows = document.querySelectorAll('tr[data-scene][data-pass]');
      for (const row of rows) {
        if (row.dataset.scene !== scene || key(row) !== pass) continue;
        if (row.dataset.speed && row.dataset.backend !== backend) continue;
        row.classList.add('accepted');
        const result = row.querySelector('td.result');
        if (result) result.textContent = 'ACCEPTED';
        const button = row.querySelector('button.accept');
        if (button) {
          button.disabled = true;
          button.textContent = 'accepted';
        }
      }
    }
  }

  // Why the pictures or timings changed: one field for the page, sent with every Accept.
  const reason = document.createElement('input');
  reason.type = 'text';
  reason.className = 'accept-reason';
  reason.placeholder = 'optional: a sentence, as in a commit message, kept beside each golden';
  reason.setAttribute('aria-label', 'why it changed');

  // What each timing golden written says (how it was written, and on a recorded host how to
  // record it again), as `bless --from-last-check` prints it: listed above the summary.
  function note(lines) {
    if (!lines || !lines.length) return;
    let list = document.querySelector('ul.accept-notes');
    if (!list) {
      list = document.createElement('ul');
      list.className = 'accept-notes';
      const summary = document.getElementById('summary');
      if (summary) summary.parentNode.insertBefore(list, summary);
      else document.body.prepend(list);
    }
    for (const line of lines) {
      const item = document.createElement('li');
      item.textContent = line;
      list.appendChild(item);
    }
  }

  function accept(filter, button) {
    button.disabled = true;
    button.textContent = 'accepting…';
    const body = Object.assign({}, filter);
    if (reason.value.trim()) body.reason = reason.value.trim();
    fetch('/accept', {
      method: 'POST',
      headers: { 'Content-Type': 'application/json', 'X-Harness-Token': review.token },
      body: JSON.stringify(body),
    })
      .then((response) => response.json())
      .then((answer) => {
        mark(answer.accepted);
        if (answer.refused.length) {
          button.disabled = false;
          button.textContent = 'refused';
          button.title = answer.refused.map((r) => r.join(' ')).join('\n');
        } else {
          button.textContent = 'accepted';
        }
        note(answer.notes);
      })
      .catch((error) => {
        button.disabled = false;
        button.textContent = 'error';
        button.title = String(error);
      });
  }

  const failing = document.querySelectorAll('table.summary tr.failed[data-scene]');
  const scenes = [];
  for (const row of failing) {
    if (!scenes.includes(row.dataset.scene)) scenes.push(row.dataset.scene);
    const button = document.createElement('button');
    button.className = 'accept';
    button.textContent = 'Accept';
    const speed = Boolean(row.dataset.speed);
    button.title = speed
      ? 'record the ratio the check measured on ' + row.dataset.backend + ' as the timing golden'
      : 'bless this output of ' + row.dataset.backend + ' as the golden';
    button.onclick = () =>
      accept(
        { scene: row.dataset.scene, pass: row.dataset.pass, backend: row.dataset.backend, speed },
        button
      );
    row.lastElementChild.prepend(button);
  }
  if (scenes.length) {
    const bar = document.createElement('div');
    bar.className = 'accept-bar';
    const label = document.createElement('label');
    label.append('Why it changed: ', reason);
    bar.append(label, document.createElement('br'), 'Accept every failing pass of: ');
    for (const scene of scenes) {
      const button = document.createElement('button');
      button.className = 'accept-scene';
      button.dataset.scene = scene;
      button.textContent = scene;
      button.onclick = () => accept({ scene }, button);
      bar.append(button);
    }
    const all = document.createElement('button');
    all.className = 'accept-run';
    all.textContent = 'the whole run';
    all.onclick = () => accept({}, all);
    bar.append(all);
    const summary = document.getElementById('summary');
    summary.parentNode.insertBefore(bar, summary.nextSibling);
  }
  mark(review.accepted);
})();

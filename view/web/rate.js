// The rating page (rate.html): shows the RatingScreen the lab's rating page sends over the
// WebSocket (view.proto, decoded with protobufjs) and sends the subject's RatingActions.
// window.cohapticRating.snapshot() gives the page's state to the browser tests
// (tests/support/rating_check.mjs).

const $ = (id) => document.getElementById(id);

async function loadSchema() {
  const root = new protobuf.Root();
  root.resolvePath = (origin, target) => (target.startsWith('/') ? target : '/proto/' + target);
  await root.load('/proto/cohaptic/view.proto', { keepCase: true });
  return { ServerMessage: root.lookupType('cohaptic.view.ServerMessage'), Command: root.lookupType('cohaptic.view.Command') };
}

class RatingPage {
  constructor(schema) {
    this.schema = schema;
    this.state = { connected: false, screens: 0, screen: null, sent: 0 };
    this.askingStop = false;
    $('switch').onclick = () => this.act({ switch_condition: {} });
    $('confirm').onclick = () => this.act({ confirm: {} });
    $('next').onclick = () => this.act({ next: {} });
    $('stop').onclick = () => this.stop();
    document.addEventListener('keydown', (e) => this.key(e));
    this.connect();
  }

  connect() {
    const token = new URLSearchParams(location.search).get('token');
    const ws = new WebSocket(`ws://${location.host}/ws${token ? `?token=${encodeURIComponent(token)}` : ''}`);
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    ws.onopen = () => { this.state.connected = true; $('connection').classList.add('hidden'); };
    ws.onmessage = (e) => {
      const message = this.schema.ServerMessage.decode(new Uint8Array(e.data));
      if (message.rating) this.show(this.schema.ServerMessage.toObject(message, { defaults: true }).rating);
    };
    ws.onclose = () => {
      this.state.connected = false;
      $('connection').textContent = 'the study is not running (or has ended): retrying…';
      $('connection').classList.remove('hidden');
      this.enable(false);
      setTimeout(() => this.connect(), 1000);
    };
  }

  // Sends one RatingAction; false when there is no connection.
  act(action) {
    if (!this.ws || this.ws.readyState !== WebSocket.OPEN) return false;
    this.ws.send(this.schema.Command.encode(this.schema.Command.create({ rating: action })).finish());
    ++this.state.sent;
    return true;
  }

  stop() {
    if (!this.askingStop) {  // a second tap, within 4 s, stops: a stray tap does not
      this.askingStop = true;
      $('stop').classList.add('asking');
      $('stop').textContent = 'Tap again to stop';
      setTimeout(() => this.resetStop(), 4000);
      return;
    }
    this.resetStop();
    this.act({ stop: {} });
  }

  resetStop() {
    this.askingStop = false;
    $('stop').classList.remove('asking');
    $('stop').textContent = 'Stop';
  }

  key(e) {
    const s = this.state.screen;
    if (!s || !s.serving || e.repeat) return;
    const key = e.key.toLowerCase();
    if (key === 's' || key === ' ') this.act({ switch_condition: {} });
    else if (key === 'n' && s.practice) this.act({ next: {} });
    else if (key === 'enter' && s.chosen) this.act({ confirm: {} });
    else if ((key === 'arrowup' || key === 'arrowdown') && !s.practice && s.grades.length) {
      const values = s.grades.map((g) => g.value);  // top to bottom
      const at = s.chosen ? values.indexOf(s.chosen_grade) : (key === 'arrowup' ? values.length : -1);
      const next = Math.min(Math.max(at + (key === 'arrowup' ? -1 : 1), 0), values.length - 1);
      this.act({ choose: values[next] });
    } else return;
    e.preventDefault();
  }

  enable(serving) {
    const s = this.state.screen;
    $('switch').disabled = !serving;
    $('confirm').disabled = !serving || !s || s.practice || !s.chosen;
    $('next').disabled = !serving || !s || !s.practice;
    $('stop').disabled = !serving;
    for (const b of document.querySelectorAll('.grade')) b.disabled = !serving;
  }

  show(s) {
    this.state.screen = s;
    ++this.state.screens;
    $('study').textContent = s.study;
    $('progress').textContent = s.pairs ? `${s.rated} of ${s.pairs} rated` : '';
    $('title').textContent = s.title || (s.serving ? '' : 'please wait');
    $('question').textContent = s.question;
    $('feeling').textContent = s.serving ? s.feeling.toUpperCase() : '—';
    $('switch').className = s.serving ? s.feeling : '';
    const grades = $('grades');
    grades.replaceChildren(...(s.serving && !s.practice ? s.grades : []).map((g) => {
      const b = document.createElement('button');
      b.className = 'grade' + (s.chosen && s.chosen_grade === g.value ? ' chosen' : '');
      b.dataset.value = String(g.value);
      b.innerHTML = `<span class="value">${g.value > 0 ? '+' : ''}${g.value}</span><span></span>`;
      b.lastChild.textContent = g.label;
      b.onclick = () => this.act({ choose: g.value });
      return b;
    }));
    $('confirm').classList.toggle('hidden', s.practice);
    $('next').classList.toggle('hidden', !s.practice);
    $('note').textContent = s.note;
    $('object').classList.toggle('hidden', !s.object_url);
    if (s.object_url) $('object-link').href = s.object_url;
    this.enable(s.serving);
  }

  snapshot() {
    return JSON.parse(JSON.stringify(this.state));
  }
}

const page = new RatingPage(await loadSchema());
window.cohapticRating = page;

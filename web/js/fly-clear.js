// Forgetting the plan to fly shown, apart from the panel that makes it (`fly.js`), so that the
// mission panel (`mission.js`), which forgets it when the mission or its conditions change, and
// the plan panel, which asks the mission panel for its pending re-plan, import no circle.

import { $, state } from './state.js';
import { el } from './dom.js';

// Forget the plan shown (the mission or its conditions changed): its layers, its links.
export function clearFly(note) {
  state.flySeq += 1;
  for (const url of state.flyUrls) URL.revokeObjectURL(url);
  state.flyUrls = [];
  if (state.flyLayer) state.flyLayer.clearLayers();
  $('#map').classList.remove('flying');
  $('#fly-title').textContent = '';
  const box = $('#fly');
  box.dataset.state = 'none';
  delete box.dataset.batteries;
  box.replaceChildren(el('p', { class: 'muted', text: note || 'The files to upload, one per battery, for this mission in these conditions.' }));
}

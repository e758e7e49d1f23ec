// dom.js — two small helpers every module of the page uses: the page's
// elements by id, and counted nouns in its texts.

/** The page's element of that id. */
export const $ = (id) => document.getElementById(id);

/** "1 member", "2 members". */
export function plural(n, word, many = word + 's') {
  return `${n} ${n === 1 ? word : many}`;
}

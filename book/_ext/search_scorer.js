/* The book's search scores (Sphinx's html_search_scorer, set by bmc_book.py): Sphinx's
 * defaults but for names of the API. A reader who types part of a function's name
 * ("knee") looks for the function: its page comes before the notebooks whose text or
 * section titles mention the word (with Sphinx's 6 points for a partial name, knee_angles
 * came 7th of 41, behind notebooks). */
var Scorer = {
  // the query is an object's full name or the last part of its dotted name
  objNameMatch: 40,
  // the query is inside the last part of the name (knee -> knee_angles)
  objPartialMatch: 25,
  // added by the object's priority (functions and classes: 1)
  objPrio: {
    0: 15,
    1: 5,
    2: -5,
  },
  objPrioDefault: 0,
  // the query in a page's or section's title
  title: 15,
  partialTitle: 7,
  // the query in the text
  term: 5,
  partialTerm: 2,
};
